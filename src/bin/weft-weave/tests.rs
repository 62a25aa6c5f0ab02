//! `weft-weave`'s flags against its generators' defaults.

use super::*;
use weft::generate::taylor::TaylorParams;
use weft::generate::woven::{Surround, WovenBandParams};
use weft::generate::woven_reduced::WovenParams;

/// The subcommand `args` with `--out` and nothing else given.
fn parse(args: &[&str]) -> Model {
    let argv = ["weft-weave"].iter().chain(args).chain(&["--out", "x"]);
    Cli::try_parse_from(argv).expect("parses").model
}

fn json<T: serde::Serialize>(t: &T) -> serde_json::Value {
    serde_json::to_value(t).expect("serialises")
}

/// Every flag left out gives the generator's `Default`: the clap defaults and the
/// flags without one (the switches) agree with the library's, and `params` maps every
/// flag onto its field.
#[test]
fn flags_left_out_give_the_generators_defaults() {
    let Model::Rod(a) = parse(&["rod"]) else {
        panic!()
    };
    assert_eq!(json(&a.params()), json(&RodParams::default()));
    let Model::Girder(a) = parse(&["girder"]) else {
        panic!()
    };
    assert_eq!(json(&a.params()), json(&GirderParams::default()));
    let Model::Membrane(a) = parse(&["membrane"]) else {
        panic!()
    };
    assert_eq!(a.options(), MembraneOptions::default());
    let Model::Membrane(a) = parse(&["membrane", "--girder-cells", "8"]) else {
        panic!()
    };
    let zone = a.options().girder_zone;
    assert_eq!(zone, Some(GirderZoneOptions::new(8)));
    let Model::Combined(a) = parse(&["combined"]) else {
        panic!()
    };
    assert_eq!(a.options(), CombinedOptions::default());
    let Model::WovenReduced(a) = parse(&["woven-reduced"]) else {
        panic!()
    };
    assert_eq!(json(&a.params()), json(&WovenParams::default()));
    let Model::Woven(a) = parse(&["woven"]) else {
        panic!()
    };
    assert_eq!(json(&a.params()), json(&WovenBandParams::default()));
    let Model::Woven(a) = parse(&["woven", "--membrane-length", "0.06"]) else {
        panic!()
    };
    assert_eq!(json(&a.params().surround), json(&Some(Surround::default())));
    let Model::Taylor(a) = parse(&["taylor"]) else {
        panic!()
    };
    assert_eq!(json(&a.params()), json(&TaylorParams::default()));
}

/// The surround's flags are shared: `woven` takes them only with --membrane-length (its
/// surround is optional), `woven-reduced` always (its surround is the model's).
#[test]
fn the_surround_flags_need_membrane_length_in_woven_alone() {
    let try_parse = |args: &[&str]| {
        let argv = ["weft-weave"].iter().chain(args).chain(&["--out", "x"]);
        Cli::try_parse_from(argv).map(|c| c.model)
    };
    for flag in [
        "--membrane-density-ratio",
        "--membrane-modulus-ratio",
        "--membrane-shear-ratio",
        "--membrane-thickness",
        "--membrane-failure-strain",
    ] {
        let Err(e) = try_parse(&["woven", flag, "0.5"]) else {
            panic!("woven {flag} without --membrane-length accepted")
        };
        assert!(e.to_string().contains("--membrane-length"), "{flag}: {e}");
        let Ok(Model::Woven(a)) = try_parse(&["woven", "--membrane-length", "0.06", flag, "0.5"])
        else {
            panic!("{flag} with --membrane-length")
        };
        assert!(a.params().surround.is_some());
        let Ok(Model::WovenReduced(a)) = try_parse(&["woven-reduced", flag, "0.5"]) else {
            panic!("woven-reduced {flag}")
        };
        let s = json(&a.params().surround);
        let field = flag.trim_start_matches("--membrane-").replace('-', "_");
        assert_eq!(s[&field], 0.5, "{flag} -> {s}");
    }
}

//! `weft-weave`'s flags against its generators' defaults.

use super::*;
use weft::generate::taylor::TaylorParams;

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

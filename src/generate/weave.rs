//! The `weave` stage behind `weft-weave`: build one canonical model from its generator's
//! parameters and write it as a model folder whose tables record those parameters.

use std::path::Path;

use super::clay::{clay_drop, ClayDropParams};
use super::rod::{build, RodParams};
use super::square::{girder, membrane, GirderParams, MembraneParams};
use super::taylor::{taylor, TaylorParams};
use super::woven::{woven, WovenBandParams};
use super::woven_reduced::{woven_reduced, WovenParams};
use super::zones::{combined, CombinedParams};
use crate::error::Result;
use crate::model::io::write_model;
use crate::model::Model;
use crate::table::Provenance;

/// Which model, with its generator's parameters.
#[derive(Debug, Clone)]
pub enum Spec {
    Rod(RodParams),
    Girder(GirderParams),
    Membrane(MembraneParams),
    Combined(CombinedParams),
    WovenReduced(WovenParams),
    Woven(WovenBandParams),
    Taylor(TaylorParams),
    ClayDrop(ClayDropParams),
}

impl Spec {
    /// The subcommand's name: `rod`, `girder`, `membrane`, `combined`, `woven-reduced`,
    /// `woven`, `taylor`, `clay-drop`.
    pub fn name(&self) -> &'static str {
        match self {
            Spec::Rod(_) => "rod",
            Spec::Girder(_) => "girder",
            Spec::Membrane(_) => "membrane",
            Spec::Combined(_) => "combined",
            Spec::WovenReduced(_) => "woven-reduced",
            Spec::Woven(_) => "woven",
            Spec::Taylor(_) => "taylor",
            Spec::ClayDrop(_) => "clay-drop",
        }
    }
}

/// Build the model, hand its generator's warnings to `on_warning`, and write it to `out`
/// with the provenance stage `weave <name>` and the parameters.
pub fn run(spec: &Spec, out: &Path, on_warning: &mut dyn FnMut(&str)) -> Result<Model> {
    let what = match spec {
        Spec::Rod(_) => "the rod model",
        Spec::Girder(_) => "the girder",
        Spec::Membrane(_) => "the membrane",
        Spec::Combined(_) => "the combined model",
        Spec::WovenReduced(_) => "the reduced woven model",
        Spec::Woven(_) => "the yarn-level woven patch",
        Spec::Taylor(_) => "the Taylor rod",
        Spec::ClayDrop(_) => "the clay's drop calibration",
    };
    let built = match spec {
        Spec::Rod(p) => build(p),
        Spec::Taylor(p) => taylor(p),
        Spec::ClayDrop(p) => clay_drop(p),
        Spec::Girder(p) => girder(p).map(|(m, warnings)| {
            warnings.iter().for_each(|w| on_warning(w));
            m
        }),
        Spec::Membrane(p) => membrane(p),
        Spec::Combined(p) => combined(p),
        Spec::WovenReduced(p) => woven_reduced(p),
        Spec::Woven(p) => woven(p).map(|(m, info)| {
            if p.yarn_model == crate::generate::woven::YarnModel::Chain {
                on_warning(&format!(
                    "note: truss chains of the lenticular section {:.4e} m² (halved on the symmetry planes), contact thickness {:.4e} m (the bands' centre thickness); crimp amplitude {:.4e} m (crimp {:.3} %); areal density {:.1} g/m² per layer",
                    info.area,
                    info.contact_thickness,
                    info.crimp_amplitude,
                    100.0 * info.crimp,
                    1e3 * info.areal_density
                ));
                return m;
            }
            on_warning(&format!(
                "note: lenticular section {:.4e} m², nodal thickness scaled by {:.4} so that the bands carry it exactly; crimp amplitude {:.4e} m (crimp {:.3} %); areal density {:.1} g/m² per layer",
                info.area,
                info.thickness_scale,
                info.crimp_amplitude,
                100.0 * info.crimp,
                1e3 * info.areal_density
            ));
            m
        }),
    };
    let m = built.map_err(|e| e.context(format!("cannot build {what}")))?;
    let parameters = match spec {
        Spec::Rod(p) => serde_json::to_value(p),
        Spec::Girder(p) => serde_json::to_value(p),
        Spec::Membrane(p) => serde_json::to_value(p),
        Spec::Combined(p) => serde_json::to_value(p),
        Spec::WovenReduced(p) => serde_json::to_value(p),
        Spec::Woven(p) => serde_json::to_value(p),
        Spec::Taylor(p) => serde_json::to_value(p),
        Spec::ClayDrop(p) => serde_json::to_value(p),
    }
    .expect("parameters serialise");
    let prov = Provenance::new(&format!("weave {}", spec.name()), parameters);
    write_model(&m, out, &prov)
        .map_err(|e| e.context(format!("cannot write model `{}`", out.display())))?;
    Ok(m)
}

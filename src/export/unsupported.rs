//! What a weft model may hold that an exporter does not reproduce faithfully: one list
//! of features ([`Unsupported`]), each found in the model the same way for every format;
//! a format names the ones it refuses, in the order it looks for them, each with its own
//! reason ([`check`]).

use crate::error::{Result, WeftError};
use crate::model::{ElementBlock, ElementKind, Model};

/// A feature of a model that an exporter may refuse.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Unsupported {
    /// Beam elements (the whole kind).
    Beams,
    /// Solid elements (hexahedra, the whole kind).
    Solids,
    /// Membrane elements, tri or quad (the whole kinds).
    Membranes,
    /// A truss's prestrain or tension-only law.
    TrussPrestrain,
    /// A truss with a cross-section area of its own (`elements_truss.parquet` `area`).
    TrussArea,
    /// A link's dashpots (cx, cy or cz > 0).
    LinkDashpots,
    /// A link's friction slider (`slip_force`).
    LinkSlider,
    /// A link's sliding ends.
    LinkSliding,
    /// A membrane's no-compression law.
    NoCompression,
    /// An element's initial stress.
    InitialStress,
    /// Rigid projectiles.
    Projectiles,
    /// Contacts between parts.
    Contacts,
    /// Tied interfaces.
    Ties,
    /// A formed model (initial displacements).
    Formed,
    /// Mass scaling (`target_time_step`).
    MassScaling,
}

/// Where a feature is looked for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scope {
    /// Whole element kinds, first.
    Kinds,
    /// Element by element (in element-table order), then.
    Element,
    /// The model's other tables, last.
    Model,
}

/// A format's refusals: (feature, the format's reason), in the order it looks for them.
pub(crate) type Refusals = [(Unsupported, &'static str)];

impl Unsupported {
    fn scope(self) -> Scope {
        use Unsupported::*;
        match self {
            Beams | Solids | Membranes => Scope::Kinds,
            TrussPrestrain | TrussArea | LinkDashpots | LinkSlider | LinkSliding
            | NoCompression | InitialStress => Scope::Element,
            Projectiles | Contacts | Ties | Formed | MassScaling => Scope::Model,
        }
    }

    /// A whole-kind or whole-model feature: what the model holds of it, if anything.
    fn in_model(self, m: &Model) -> Option<String> {
        use Unsupported::*;
        let held = |yes: bool, what: &str| yes.then(|| what.to_string());
        match self {
            Beams => held(m.block(ElementKind::Beam).is_some(), "beam elements"),
            Solids => held(m.block(ElementKind::Hex).is_some(), "solid elements (hex)"),
            Membranes => [ElementKind::Tri, ElementKind::Quad]
                .into_iter()
                .find(|&k| m.block(k).is_some())
                .map(|k| format!("membrane elements ({})", k.name())),
            Projectiles => held(!m.projectiles.is_empty(), "projectiles"),
            Contacts => held(!m.contacts.is_empty(), "contacts between parts"),
            Ties => held(!m.ties.is_empty(), "tied interfaces"),
            Formed => held(
                !m.initial_displacement.is_empty(),
                "a formed model (initial displacements ux0, uy0, uz0)",
            ),
            MassScaling => held(
                m.analysis.target_time_step.is_some(),
                "mass scaling (target_time_step)",
            ),
            _ => None,
        }
    }

    /// A per-element feature: what element `e` of block `b` (of `kind`) holds of it, if
    /// anything (named with its part by [`check`]).
    fn in_element(
        self,
        m: &Model,
        kind: ElementKind,
        b: &ElementBlock,
        e: usize,
    ) -> Option<&'static str> {
        use Unsupported::*;
        let p = &m.parts[b.part[e]].props;
        let (truss, link) = (kind == ElementKind::Truss, kind == ElementKind::Link);
        let membrane = matches!(kind, ElementKind::Tri | ElementKind::Quad);
        let (yes, what) = match self {
            TrussPrestrain => (
                truss && (p.prestrain.unwrap_or(0.0) != 0.0 || p.tension_only.unwrap_or(false)),
                "the prestrain or tension-only law",
            ),
            TrussArea => (
                truss && b.truss_area(&m.parts, e) != p.area.unwrap_or(0.0),
                "a cross-section area of its own (elements_truss.parquet `area`)",
            ),
            LinkDashpots => (
                link && [p.cx, p.cy, p.cz]
                    .iter()
                    .any(|c| c.is_some_and(|c| c > 0.0)),
                "the dashpots",
            ),
            LinkSlider => (link && p.slip_force.is_some(), "the friction slider"),
            LinkSliding => (link && p.sliding == Some(true), "the sliding ends"),
            NoCompression => (
                membrane && p.no_compression.unwrap_or(false),
                "the no-compression law",
            ),
            InitialStress => (
                !b.stress0.is_empty() && b.stress0[e] != [0.0; 3],
                "the initial stress",
            ),
            _ => (false, ""),
        };
        yes.then_some(what)
    }
}

/// Refusal: the model holds something the format cannot reproduce faithfully.
pub(crate) fn refuse(format: &str, what: &str, why: &str) -> WeftError {
    WeftError::input(format!("cannot export {what} to {format}: {why}"))
        .hint("export a model without it (the deck would not be the same model), or compare it in weft alone")
}

/// The first of `refusals` the model holds, as an error: whole element kinds first, then
/// element by element (each element's features in the format's order), then the rest of
/// the model.
pub(crate) fn check(m: &Model, format: &str, refusals: &Refusals) -> Result<()> {
    let of = |scope: Scope| refusals.iter().filter(move |r| r.0.scope() == scope);
    for &(f, why) in of(Scope::Kinds) {
        if let Some(what) = f.in_model(m) {
            return Err(refuse(format, &what, why));
        }
    }
    for (&kind, b) in &m.elements {
        for e in 0..b.len() {
            for &(f, why) in of(Scope::Element) {
                if let Some(what) = f.in_element(m, kind, b, e) {
                    let part = &m.parts[b.part[e]];
                    let what = format!("{what} of {} part `{}`", kind.name(), part.name);
                    return Err(refuse(format, &what, why));
                }
            }
        }
    }
    for &(f, why) in of(Scope::Model) {
        if let Some(what) = f.in_model(m) {
            return Err(refuse(format, &what, why));
        }
    }
    Ok(())
}

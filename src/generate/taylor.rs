//! `taylor`: the Taylor test (Taylor 1948, *Proc. R. Soc. A* 194, 289): a flat-ended
//! cylinder of length L and diameter D, along z from z = 0 to L, strikes a rigid,
//! frictionless wall (the plane z = 0, a prescribed `wall` projectile) at U.
//!
//! Quarter model: symmetry planes x = 0 and y = 0; the quarter disk of radius D/2 is
//! an O-grid ([`super::cylinder::quarter_disk`]) of `radial` cells from the axis to the
//! rim (half in the core, half in the ring), `axial` layers along z (default: cells as
//! long as they are wide, L/(D/2/radial)). Every node starts at (0, 0, −U). One part
//! `rod` of the named metal (Johnson–Cook) or, with `yield_stress`, of the metal's
//! elasticity and density with J2 perfect plasticity (Taylor's own material, for the
//! comparison with his one-dimensional theory). The step follows the crushed foot
//! (`variable_time_step`).
//!
//! Node sets: `axis` (x = y = 0), `impact_face` (z = 0), `impact_edge` (the impact face's
//! rim, r = D/2: the foot's diameter), `rear_face` (z = L).

use serde::Serialize;

use super::cylinder::{extrude, quarter_disk};
use super::metals::Metal;
use crate::error::{Result, WeftError};
use crate::model::{
    Analysis, ElementKind, Model, PartProps, ProjectileShape, ProjectileSpec, SymmetryPlane,
};

#[derive(Debug, Clone, Serialize)]
pub struct TaylorParams {
    /// Rod length L [m].
    pub length: f64,
    /// Rod diameter D [m].
    pub diameter: f64,
    /// Impact velocity U [m/s] (towards the wall).
    pub velocity: f64,
    pub material: Metal,
    /// J2 perfect plasticity at this yield stress [Pa] instead of Johnson–Cook.
    pub yield_stress: Option<f64>,
    /// Cells from the axis to the rim (even, ≥ 2).
    pub radial: usize,
    /// Layers along the rod; `None`: cells as long as they are wide.
    pub axial: Option<usize>,
    /// Hourglass coefficient Q_hg.
    pub hourglass: f64,
    /// Coulomb friction of the wall.
    pub wall_friction: f64,
    /// End time [s]; `None`: 0.6 L/U.
    pub end_time: Option<f64>,
    /// Output interval [s]; `None`: the end time / 100.
    pub output_interval: Option<f64>,
}

impl Default for TaylorParams {
    /// Johnson & Cook's (1983) OFHC copper rod: 25.4 mm long, 7.6 mm across, at 190 m/s.
    fn default() -> Self {
        TaylorParams {
            length: 25.4e-3,
            diameter: 7.6e-3,
            velocity: 190.0,
            material: Metal::Copper,
            yield_stress: None,
            radial: 4,
            axial: None,
            hourglass: 0.1,
            wall_friction: 0.0,
            end_time: None,
            output_interval: None,
        }
    }
}

impl TaylorParams {
    /// The layers along the rod.
    pub fn layers(&self) -> usize {
        self.axial.unwrap_or_else(|| {
            ((self.length / (0.5 * self.diameter / self.radial as f64)).round() as usize).max(1)
        })
    }
    pub fn end(&self) -> f64 {
        self.end_time.unwrap_or(0.6 * self.length / self.velocity)
    }
}

fn check(p: &TaylorParams) -> Result<()> {
    let positive = |name: &str, v: f64, unit: &str| {
        if v > 0.0 && v.is_finite() {
            Ok(())
        } else {
            Err(
                WeftError::input(format!("taylor parameter --{name} = `{v}`"))
                    .expected(format!("a value > 0 {unit}")),
            )
        }
    };
    positive("length", p.length, "m")?;
    positive("diameter", p.diameter, "m")?;
    positive("velocity", p.velocity, "m/s")?;
    positive("hourglass", p.hourglass, "")?;
    if let Some(y) = p.yield_stress {
        positive("yield-stress", y, "Pa")?;
    }
    if let Some(t) = p.end_time {
        positive("end-time", t, "s")?;
    }
    if let Some(t) = p.output_interval {
        positive("output-interval", t, "s")?;
    }
    if !(p.wall_friction >= 0.0 && p.wall_friction.is_finite()) {
        return Err(WeftError::input(format!(
            "taylor parameter --wall-friction = `{}`",
            p.wall_friction
        ))
        .expected("a Coulomb coefficient ≥ 0"));
    }
    if p.radial < 2 || p.radial % 2 != 0 {
        return Err(
            WeftError::input(format!("taylor parameter --radial = `{}`", p.radial))
                .expected("an even number ≥ 2 (half the cells in the core, half in the ring)"),
        );
    }
    if p.axial == Some(0) {
        return Err(WeftError::input("taylor parameter --axial = `0`").expected("at least 1 layer"));
    }
    Ok(())
}

pub fn taylor(p: &TaylorParams) -> Result<Model> {
    check(p)?;
    let r = 0.5 * p.diameter;
    let disk = quarter_disk(r, p.radial / 2, p.radial / 2);
    let nz = p.layers();
    let z: Vec<f64> = (0..=nz).map(|k| p.length * k as f64 / nz as f64).collect();
    let (nodes, hexes) = extrude(&disk, &z, &vec![1.0; z.len()]);
    let mut m = Model::default();
    for (i, x) in nodes.iter().enumerate() {
        m.add_node(i as i64 + 1, *x);
        m.initial_velocities.push((i, [0.0, 0.0, -p.velocity]));
    }
    let props = match p.yield_stress {
        None => p.material.part_props(p.hourglass, None),
        Some(y) => {
            let k = p.material.constants();
            PartProps {
                density: Some(k.density),
                youngs_modulus: Some(k.youngs_modulus),
                poisson_ratio: Some(k.poisson_ratio),
                hourglass: Some(p.hourglass),
                yield_stress: Some(y),
                tangent_modulus: Some(0.0),
                ..Default::default()
            }
        }
    };
    let part = m.add_part(1, "rod", ElementKind::Hex, props);
    for (e, h) in hexes.iter().enumerate() {
        m.add_element(e as i64 + 1, part, h);
    }
    let tol = 1e-9 * r;
    let set = |f: &dyn Fn(&[f64; 3]) -> bool| -> Vec<usize> {
        (0..nodes.len()).filter(|&i| f(&nodes[i])).collect()
    };
    let rim = |x: &[f64; 3]| (x[0].hypot(x[1]) - r).abs() < tol;
    m.node_sets.insert(
        "axis".into(),
        set(&|x| x[0].abs() < tol && x[1].abs() < tol),
    );
    m.node_sets
        .insert("impact_face".into(), set(&|x| x[2].abs() < tol));
    m.node_sets
        .insert("impact_edge".into(), set(&|x| x[2].abs() < tol && rim(x)));
    m.node_sets
        .insert("rear_face".into(), set(&|x| (x[2] - p.length).abs() < tol));
    for normal in 0..2 {
        m.symmetry.push(SymmetryPlane {
            normal,
            position: 0.0,
            tolerance: tol,
        });
    }
    m.projectiles.push(ProjectileSpec {
        id: 1,
        shape: ProjectileShape::Wall,
        radius: 2.0 * p.diameter,
        length: p.diameter,
        mass: 1.0,
        tip: [0.0; 3],
        axis: [0.0, 0.0, 1.0],
        velocity: [0.0; 3],
        prescribed_velocity: true,
        contact_stiffness: None,
        friction: p.wall_friction,
        contact_damping: 0.0,
        segment_contact: false,
    });
    let end = p.end();
    m.analysis = Analysis {
        end_time: end,
        output_interval: p.output_interval.unwrap_or(end / 100.0),
        history_sets: vec!["axis".into(), "impact_edge".into()],
        variable_time_step: true,
        ..Default::default()
    };
    m.validate()?;
    Ok(m)
}

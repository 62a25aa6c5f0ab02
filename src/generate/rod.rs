//! `rod`: a straight chain of trusses along x, fixed at x = 0, with an axial force pulse
//! F(t) = F₀ sin(πt/T_F) on [0, T_F] at the free end x = L.
//!
//! Longitudinal wave speed c = √(E/ρ); default pulse duration T_F = ½ L √(ρ/E) (the pulse
//! spans half the rod); default end time 2L/c (the pulse reaches the fixed end and comes
//! back). Transverse directions are fixed (a 1-D problem).

use serde::Serialize;

use crate::error::{Result, WeftError};
use crate::model::{Analysis, ElementKind, Load, Model, PartProps, TimeLaw};

#[derive(Debug, Clone, Serialize)]
pub struct RodParams {
    /// Rod length L [m].
    pub length: f64,
    /// Number of truss elements.
    pub elements: usize,
    /// Young's modulus E [Pa].
    pub youngs_modulus: f64,
    /// Density ρ [kg/m³].
    pub density: f64,
    /// Section width [m].
    pub width: f64,
    /// Section thickness [m].
    pub thickness: f64,
    /// Force amplitude F₀ [N] (positive pulls along +x).
    pub force: f64,
    /// Pulse duration T_F [s]; `None`: ½ L √(ρ/E).
    pub pulse_duration: Option<f64>,
    /// End time [s]; `None`: 2 L/c.
    pub end_time: Option<f64>,
    /// Output interval [s]; `None`: end time / 400.
    pub output_interval: Option<f64>,
    pub tension_only: bool,
}

impl Default for RodParams {
    fn default() -> Self {
        RodParams {
            length: 0.1,
            elements: 200,
            youngs_modulus: 1.5e11,
            density: 7800.0,
            width: 1e-3,
            thickness: 1e-3,
            force: 100.0,
            pulse_duration: None,
            end_time: None,
            output_interval: None,
            tension_only: false,
        }
    }
}

impl RodParams {
    pub fn wave_speed(&self) -> f64 {
        (self.youngs_modulus / self.density).sqrt()
    }
    pub fn pulse(&self) -> f64 {
        self.pulse_duration
            .unwrap_or(0.5 * self.length / self.wave_speed())
    }
}

fn positive(name: &str, v: f64, unit: &str) -> Result<()> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(WeftError::input(format!("rod parameter --{name} = `{v}`"))
            .expected(format!("a value > 0 {unit}")))
    }
}

pub fn build(p: &RodParams) -> Result<Model> {
    positive("length", p.length, "m")?;
    positive("youngs-modulus", p.youngs_modulus, "Pa")?;
    positive("density", p.density, "kg/m³")?;
    positive("width", p.width, "m")?;
    positive("thickness", p.thickness, "m")?;
    if let Some(d) = p.pulse_duration {
        positive("pulse-duration", d, "s")?;
    }
    if p.elements == 0 {
        return Err(
            WeftError::input("rod parameter --elements = `0`").expected("at least 1 element")
        );
    }
    if !p.force.is_finite() {
        return Err(
            WeftError::input(format!("rod parameter --force = `{}`", p.force))
                .expected("a finite force in N"),
        );
    }
    let c = p.wave_speed();
    let mut m = Model::default();
    let n = p.elements;
    let h = p.length / n as f64;
    for i in 0..=n {
        m.add_node(i as i64 + 1, [i as f64 * h, 0.0, 0.0]);
    }
    let part = m.add_part(
        1,
        "rod",
        ElementKind::Truss,
        PartProps {
            youngs_modulus: Some(p.youngs_modulus),
            density: Some(p.density),
            area: Some(p.width * p.thickness),
            tension_only: Some(p.tension_only),
            ..Default::default()
        },
    );
    for e in 0..n {
        m.add_element(e as i64 + 1, part, &[e, e + 1]);
    }
    m.constraints.push((0, [true, true, true]));
    for i in 1..=n {
        m.constraints.push((i, [false, true, true]));
    }
    m.loads.push(Load {
        id: 1,
        node: n,
        force: [p.force, 0.0, 0.0],
        law: TimeLaw::SinePulse {
            start: 0.0,
            duration: p.pulse(),
        },
    });
    let all: Vec<usize> = (0..=n).collect();
    m.node_sets.insert("axis_x".into(), all.clone());
    m.node_sets.insert("reference".into(), all);
    m.node_sets.insert("free_end".into(), vec![n]);
    m.node_sets.insert("fixed_end".into(), vec![0]);
    let end = p.end_time.unwrap_or(2.0 * p.length / c);
    m.analysis = Analysis {
        end_time: end,
        output_interval: p.output_interval.unwrap_or(end / 400.0),
        ..Default::default()
    };
    m.validate()?;
    Ok(m)
}

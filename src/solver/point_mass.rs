//! Point masses: a lumped mass m [kg] added to one node. They exert no force, store no
//! energy and do not limit the step; they are a family so that a model's `point_mass`
//! block is built like every other (and could later carry rotary inertia).

use super::family::{Build, EnergyGroup, EnergyPartial, Family, ForceCtx, StiffCtx};
use crate::error::Result;
use crate::model::ElementKind;

/// Point masses, struct-of-arrays.
#[derive(Debug, Clone, Default)]
pub struct PointMassGroup {
    pub id: Vec<i64>,
    pub node: Vec<u32>,
    pub mass: Vec<f64>,
}

impl Family for PointMassGroup {
    const KIND: ElementKind = ElementKind::PointMass;
    const SLOTS: usize = 0;
    const GROUP: EnergyGroup = EnergyGroup::Line;

    fn build(bd: &mut Build) -> Result<Self> {
        let m = bd.model;
        let mut g = PointMassGroup::default();
        let Some(b) = m.block(ElementKind::PointMass) else {
            return Ok(g);
        };
        for e in 0..b.len() {
            let mp = m.parts[b.part[e]].props.mass.unwrap();
            bd.mass[b.nodes[e]] += mp;
            g.id.push(b.id[e]);
            g.node.push(b.nodes[e] as u32);
            g.mass.push(mp);
        }
        Ok(g)
    }
    fn len(&self) -> usize {
        self.id.len()
    }
    fn id(&self, e: usize) -> i64 {
        self.id[e]
    }
    fn slot_nodes(&self, _e: usize) -> &[u32] {
        &[]
    }
    fn stiffness(&self, _e: usize) -> f64 {
        0.0
    }
    fn forces(&mut self, _ctx: &ForceCtx, _fe: &mut [[f64; 3]]) {}
    fn stiffness_sums(&self, _: &StiffCtx, _: &mut [f64], _: &mut [f64], _: &mut [f64]) {}
    fn energies(&mut self, _ctx: &ForceCtx) -> &[EnergyPartial] {
        &[]
    }
}

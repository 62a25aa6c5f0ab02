//! What a run's failures leave, and what an armour engineer reads while it goes: the
//! failures logged ([`super::FailureLog`]), the failed elements taken out of the contact
//! surfaces after each force pass, and the per-layer values and the projectile's
//! outcome at each output sample ([`super::watch`]).

use super::vec3::dot;
use super::{failure, watch, Solver};
use crate::model::ElementKind;

/// The projectile as the watch judges it at a sample: its tip, velocity, the contact
/// force on it and its radius; a deformable bullet's mass (`None`: a rigid projectile).
#[derive(Debug, Clone, Copy)]
struct Striker {
    tip: [f64; 3],
    v: [f64; 3],
    force: [f64; 3],
    radius: f64,
    bullet_mass: Option<f64>,
}

impl Solver {
    /// The watch at a sample step (t_n, x^n, v^n): each layer's values into `rows` (layer
    /// 1 first), the last layer's deflection peak, the plies perforated and the
    /// projectile's outcome.
    pub(super) fn watch_sample(&mut self, rows: &mut Vec<watch::LayerValues>) {
        let w = &self.watch;
        let axis = w.axis().unwrap_or([0.0, 0.0, -1.0]);
        let n = w.n_layers;
        rows.clear();
        rows.resize(n, [0.0; 10]);
        let proj = self
            .op
            .projectiles
            .projectiles
            .first()
            .map(|p| Striker {
                tip: p.tip,
                v: p.v_full,
                force: p.force,
                radius: p.radius,
                bullet_mass: None,
            })
            .or_else(|| self.bullet_state());
        let tip_a = proj.map_or(f64::INFINITY, |p| dot(&p.tip, &axis));
        let on_cap = w.cap_layers(&self.state.xn, tip_a);
        let (xn, vn, x0) = (&self.state.xn, &self.state.vn, &self.x0);
        let fr_s = self.op.surfaces.node_friction.as_deref();
        let fr_p = self.op.projectiles.node_friction.as_deref();
        for i in 0..xn.len() {
            let attached = self.failures.is_attached(i);
            let l = w.node_layer(i) as usize;
            if l == 0 {
                continue;
            }
            let r = &mut rows[l - 1];
            r[0] += 0.5 * self.mass[i] * dot(&vn[i], &vn[i]);
            r[3] += fr_s.map_or(0.0, |f| f[i]) + fr_p.map_or(0.0, |f| f[i]);
            if attached {
                let u = [
                    xn[i][0] - x0[i][0],
                    xn[i][1] - x0[i][1],
                    xn[i][2] - x0[i][2],
                ];
                r[7] = r[7].max(dot(&u, &axis));
            }
        }
        // The yarn-to-yarn contact springs: a pair's stored energy to its slave's layer.
        for side in &self.op.surfaces.sides {
            for (o, &s) in side.out.iter().zip(&side.slaves) {
                let l = w.node_layer(s as usize) as usize;
                if l > 0 && o.face != u32::MAX {
                    rows[l - 1][1] += o.stored;
                }
            }
        }
        self.op.el.for_layer_energies(xn, |kind, e, energies| {
            let l = w.element_layer(kind, e) as usize;
            if l > 0 {
                let (stored, eroded) = energies();
                rows[l - 1][1] += stored;
                rows[l - 1][2] += eroded;
            }
        });
        for (l, r) in rows.iter_mut().enumerate() {
            r[4] = r[0] + r[1] + r[2] + r[3];
            let (failed, broken) = w.counts(l + 1);
            r[5] = failed as f64;
            r[6] = broken as f64;
            r[8] = w.first_failure[l + 1];
        }
        let back = rows.last().map_or(0.0, |r| r[7]);
        let t = self.state.t;
        let w = &mut self.watch;
        w.back_face_peak = w.back_face_peak.max(back);
        if let Some(p) = proj {
            // A deformable bullet: the contact forces' mean over the last samples, not
            // their value now (fragments ring on its faces: `Watch::bullet_force`).
            let f = p
                .bullet_mass
                .and_then(|m| w.bullet_force(t, &p.v, m))
                .unwrap_or(p.force);
            w.judge(t, &p.tip, &p.v, &f, p.radius, &on_cap);
        }
        for (l, r) in rows.iter_mut().enumerate() {
            r[9] = w.perforated_at(l + 1);
        }
        w.last_rows.clone_from(rows);
    }

    /// A deformable bullet as the watch judges it at t_n: its most advanced node's
    /// position as the tip, its momentum over its mass as the velocity, the contact forces
    /// on its nodes summed, its radius, its mass.
    fn bullet_state(&self) -> Option<Striker> {
        let w = &self.watch;
        let a = w.axis()?;
        if w.bullet.is_empty() {
            return None;
        }
        let (xn, vn, fcon) = (&self.state.xn, &self.state.vn, &self.op.fcon);
        let (mut tip, mut best) = ([0.0; 3], f64::NEG_INFINITY);
        let (mut p, mut m, mut f) = ([0.0; 3], 0.0, [0.0; 3]);
        for &i in &w.bullet {
            let s = dot(&xn[i], &a);
            if s > best {
                (tip, best) = (xn[i], s);
            }
            m += self.mass[i];
            for d in 0..3 {
                p[d] += self.mass[i] * vn[i][d];
                f[d] += fcon[i][d];
            }
        }
        Some(Striker {
            tip,
            v: [p[0] / m, p[1] / m, p[2] / m],
            force: f,
            radius: w.bullet_radius,
            bullet_mass: Some(m),
        })
    }

    /// The failures of the force pass just done: logged, their nodes' attachments
    /// counted down, and the failed elements' faces and segments out of the contact
    /// surfaces (projectiles' and between parts) before contact is computed.
    pub(super) fn apply_failures(&mut self) {
        let log = &mut self.failures;
        log.collected.clear();
        self.op
            .el
            .collect_failures(&mut log.scratch, &mut log.collected);
        for c in log.collected.drain(..) {
            let f = c.failure;
            log.events.push(failure::FailureEvent {
                time: self.state.t,
                step: self.state.step,
                id: c.id,
                failure: f,
            });
            if f.eroded {
                for &n in &c.nodes {
                    let a = &mut log.attached[n as usize];
                    *a = a.saturating_sub(1);
                }
                if f.kind == ElementKind::Hex {
                    // A solid's faces leave the surfaces they belong to, uncovering its
                    // neighbours' (an eroding solid's interior faces, `contact::surface::solid`).
                    self.op.surfaces.erode(f.kind, f.element);
                }
                if matches!(
                    f.kind,
                    ElementKind::Truss | ElementKind::Tri | ElementKind::Quad
                ) {
                    self.op.surfaces.erode(f.kind, f.element);
                    self.op.projectiles.erode(f.kind, f.element);
                    self.watch.on_erosion(f.kind, f.element, self.state.t);
                }
            }
        }
    }
}

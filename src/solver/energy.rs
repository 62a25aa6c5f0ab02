//! The energy ledger: the energies of a state ([`Energies`], [`ElementEnergies`]) and
//! the running balance E_kin + E_int + dissipated + contact − E₀ − W_ext that a run books
//! at every output sample and checks ([`Ledger`], [`ENERGY_CHECK_AFTER`]).

/// The energy-balance stop applies from this step on. In the first steps every energy
/// is O(Δt⁴) and the trapezoidal external work lags the kinetic energy by a relative O(1)
/// (Belytschko et al. §6.2.3); an instability grows exponentially and is caught soon
/// after. NaN and infinity are caught from the first step.
pub const ENERGY_CHECK_AFTER: u64 = 100;

/// Energies at one time [J].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energies {
    pub kinetic: f64,
    /// Stored elastic energy of all elements.
    pub internal: f64,
    /// Dissipated by dashpots and mass-proportional damping.
    pub damping: f64,
    /// Dissipated by friction sliders.
    pub friction: f64,
    /// Hourglass energy (membrane quads).
    pub hourglass: f64,
    /// Contact energy: stored penalty energy and friction work in contact.
    pub contact: f64,
    /// Strain energy taken out of the model by failed elements, with the contact energy
    /// their faces held when they left (docs/theory.md, "Failure, perforation and the
    /// ballistic limit"; `contact::SurfaceContact::eroded`).
    pub eroded: f64,
    pub external_work: f64,
    /// kinetic + internal + damping + friction + hourglass + contact + eroded − initial −
    /// external work.
    pub balance_error: f64,
    /// |balance_error| over the energy scale so far, [`Energies::scale`].
    pub balance_error_relative: f64,
    /// Energy scale so far: max(|initial|, |external work|, kinetic + |internal|) over
    /// the samples up to this one, and never below the round-off floor of the model (the
    /// kinetic energy of its whole mass moving 10⁻¹² of its size per step) [J].
    pub scale: f64,
}

impl Energies {
    pub(super) fn lerp(&self, o: &Energies, w: f64) -> Energies {
        let l = |a: f64, b: f64| a + w * (b - a);
        Energies {
            kinetic: l(self.kinetic, o.kinetic),
            internal: l(self.internal, o.internal),
            damping: l(self.damping, o.damping),
            friction: l(self.friction, o.friction),
            hourglass: l(self.hourglass, o.hourglass),
            contact: l(self.contact, o.contact),
            eroded: l(self.eroded, o.eroded),
            external_work: l(self.external_work, o.external_work),
            balance_error: l(self.balance_error, o.balance_error),
            balance_error_relative: l(self.balance_error_relative, o.balance_error_relative),
            scale: l(self.scale, o.scale),
        }
    }
}

/// Element energies at one state [J].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ElementEnergies {
    /// Stored elastic energy.
    pub internal: f64,
    /// Dissipated by dashpots so far.
    pub damping: f64,
    /// Dissipated by link sliders so far.
    pub friction: f64,
    pub hourglass: f64,
    /// Taken by failed elements so far (with the contact energy their faces held).
    pub eroded: f64,
}

/// The energy ledger: the running balance E_kin + E_int + dissipated + contact − E₀ −
/// W_ext, checked at every output sample.
#[derive(Debug, Clone, Default)]
pub(super) struct Ledger {
    /// Energy dissipated by mass-proportional damping [J] (trapezoidal in time).
    pub(super) mass_damping: f64,
    /// Total energy at the first sample.
    e0: Option<f64>,
    /// Reference energy max(|E₀|, |W_ext|, E_kin + |E_int|) so far, at least `floor`.
    pub(super) reference: f64,
    /// Round-off floor of the reference [J] (see [`Energies::scale`]): a model with no
    /// load and no initial velocity has only round-off energies (~1e-27 J), which must
    /// not be judged against each other.
    pub(super) floor: f64,
    max_rel: f64,
    last_rel: f64,
}

impl Ledger {
    /// Books the energies at t_n; the relative balance error.
    pub(super) fn book(
        &mut self,
        ke: f64,
        el: &ElementEnergies,
        contact: f64,
        w_ext: f64,
        step: u64,
    ) -> Energies {
        let (ie, damp, fric, hg) = (el.internal, el.damping, el.friction, el.hourglass);
        let mut total = ke + ie + damp + self.mass_damping + fric + hg + contact;
        if el.eroded != 0.0 {
            total += el.eroded;
        }
        let e_init = *self.e0.get_or_insert(total);
        let err = total - e_init - w_ext;
        // |E_int|: with initial stresses the stored energy ½E·DE + S₀·E can be negative.
        self.reference = self
            .reference
            .max(self.floor)
            .max(e_init.abs())
            .max(w_ext.abs())
            .max(ke + ie.abs());
        let rel = if self.reference > 0.0 {
            err.abs() / self.reference
        } else {
            0.0
        };
        if step >= ENERGY_CHECK_AFTER {
            self.max_rel = self.max_rel.max(rel);
        }
        self.last_rel = rel;
        Energies {
            kinetic: ke,
            internal: ie,
            damping: damp + self.mass_damping,
            friction: fric,
            hourglass: hg,
            contact,
            eroded: el.eroded,
            external_work: w_ext,
            balance_error: err,
            balance_error_relative: rel,
            scale: self.reference,
        }
    }
    /// The run's balance: the worst after ENERGY_CHECK_AFTER steps, else the last.
    pub(super) fn reported(&self, steps: u64) -> f64 {
        if steps >= ENERGY_CHECK_AFTER {
            self.max_rel
        } else {
            self.last_rel
        }
    }
}

/// Round-off floor of the energy scale [J]: ½ M (10⁻¹² L/Δt)², the kinetic energy of
/// the model's mass M moving 10⁻¹² of its size L (bounding-box diagonal) per step. Round-off
/// motion (positions to ~2·10⁻¹⁶ L) is ~10⁸ times below it; a loaded model's energies are
/// many orders above it.
pub(super) fn energy_floor(x: &[[f64; 3]], mass: &[f64], dt: f64) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in x {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let l2: f64 = (0..3).map(|d| (hi[d] - lo[d]).powi(2)).sum();
    let m: f64 = mass.iter().filter(|m| m.is_finite()).sum();
    if !(dt > 0.0) || !l2.is_finite() {
        return 0.0;
    }
    0.5 * m * 1e-24 * l2 / (dt * dt)
}

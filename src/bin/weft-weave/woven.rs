//! `weft-weave woven`'s flags: the yarn-level patch's own, and the groups it shares with
//! `woven-reduced` ([`super::fabric`]).

use weft::generate::clay;
use weft::generate::weave::Spec;
use weft::generate::woven::{Edge, StrengthPer, Surround, WovenBandParams, YarnFailure, YarnModel};

use super::fabric::{BallisticArgs, OutArgs, PatchArgs, ProjectileArgs, RunArgs, SurroundArgs};

#[derive(clap::Args)]
#[command(mut_group("SurroundArgs", |g| g.requires("membrane_length")))]
pub struct WovenBandArgs {
    #[command(flatten)]
    pub out: OutArgs,
    /// Yarns per side: of the quarter (the middle yarn counted once) or, with --full, of
    /// the whole patch (even). 60: the paper's 120 × 120 reference; a small patch alone
    /// at 400 m/s, without yarn failure, strains beyond validity within microseconds.
    #[arg(long, default_value_t = WovenBandParams::default().yarns)]
    yarns: usize,
    #[command(flatten)]
    patch: PatchArgs<WovenBandParams>,
    /// Yarn width w [m].
    #[arg(long, default_value_t = WovenBandParams::default().width)]
    width: f64,
    /// Yarn thickness h [m] (lenticular section: area ≈ (2/3)wh).
    #[arg(long, default_value_t = WovenBandParams::default().thickness)]
    thickness: f64,
    /// Crimp amplitude a [m] (default: crossing yarns just touch).
    #[arg(long)]
    crimp_amplitude: Option<f64>,
    /// Quads per spacing along a yarn (even, ≥ 4).
    #[arg(long, default_value_t = WovenBandParams::default().per_spacing)]
    per_spacing: usize,
    /// Quads across a yarn's width (even, ≥ 2).
    #[arg(long, default_value_t = WovenBandParams::default().across)]
    across: usize,
    /// How each yarn is modelled: `band`, the paper's reference (orthotropic membrane
    /// quads across the width, contact on the lenticular band faces), or `chain`, trusses
    /// along the band's centre line with the band's section and mass and its centre
    /// thickness as contact thickness (no width: 4–6 × faster; the yarn on a symmetry
    /// plane has half the section; the projectile's nose grows by half that thickness,
    /// its tip as much lower, so that it meets the yarns' surfaces).
    #[arg(long, value_enum, default_value_t = WovenBandParams::default().yarn_model)]
    yarn_model: YarnModel,
    /// Yarn Young's modulus along the yarn [Pa] (aramid, Kevlar 29 class).
    #[arg(long, default_value_t = WovenBandParams::default().modulus)]
    modulus: f64,
    /// Yarn modulus across its width [Pa] (a bundle of filaments: small).
    #[arg(long, default_value_t = WovenBandParams::default().transverse_modulus)]
    transverse_modulus: f64,
    /// Yarn in-plane shear modulus [Pa].
    #[arg(long, default_value_t = WovenBandParams::default().shear_modulus)]
    shear_modulus: f64,
    /// Yarn density [kg/m³].
    #[arg(long, default_value_t = WovenBandParams::default().density)]
    density: f64,
    /// Yarn–yarn Coulomb friction coefficient.
    #[arg(long, default_value_t = WovenBandParams::default().friction)]
    friction: f64,
    /// Yarns carry no compression (tension field; its stress has no potential, so the
    /// energy balance drifts where the yarns are crushed).
    #[arg(long)]
    tension_field: bool,
    /// Fabric layers.
    #[arg(long, default_value_t = WovenBandParams::default().layers)]
    layers: usize,
    /// Clearance between layers [m].
    #[arg(long, default_value_t = WovenBandParams::default().layer_gap)]
    layer_gap: f64,
    /// Yarn ends at the patch edge: clamped (all nodes held), pinned (centre-line node
    /// held) or free. Ignored with --membrane-length (the ends are tied).
    #[arg(long, value_enum, default_value_t = WovenBandParams::default().edge)]
    edge: Edge,
    /// The paper's §3 combined model: tie the quarter patch's yarn ends to a graded
    /// orthotropic membrane around it, out to this half-size [m] (e.g. 0.06, the
    /// 60 × 60-yarn reference's), clamped at its outer edge. Adds the node sets
    /// `interface` (the tied yarn ends) and `axis_x_all` (the x axis through both). The
    /// --membrane-* flags below need it.
    #[arg(long)]
    membrane_length: Option<f64>,
    /// With --membrane-length: growth ratio of the membrane's cells (p/2 at the patch) outwards.
    #[arg(long, requires = "membrane_length", default_value_t = Surround::default().growth)]
    membrane_growth: f64,
    #[command(flatten)]
    surround: SurroundArgs,
    #[command(flatten)]
    projectile: ProjectileArgs<WovenBandParams>,
    #[command(flatten)]
    run: RunArgs<WovenBandParams>,
    /// Yarn failure strain along the yarn (0: the yarns never fail, as in the paper's
    /// studies). Aramid yarn: 0.036 (Kevlar 29 yarn, 2.92 GPa at 3.6 %; the fibre's 4.0 %
    /// is an upper bound); with --weibull-modulus, the Weibull scale at the gauge length.
    #[arg(long, default_value_t = YarnFailure::default().strain)]
    failure_strain: f64,
    /// Statistical strengths: the Weibull modulus m of the failure strains (Kevlar yarns:
    /// 8–22), drawn from --seed per yarn or per element; left out, every yarn fails at
    /// --failure-strain.
    #[arg(long)]
    weibull_modulus: Option<f64>,
    /// Gauge length L₀ [m] of the Weibull scale [default: each yarn's modelled length].
    #[arg(long)]
    weibull_gauge_length: Option<f64>,
    /// Draw the strengths per yarn or per element (weakest link).
    #[arg(long, value_enum, default_value_t = YarnFailure::default().per)]
    strength_per: StrengthPer,
    /// Seed of the strengths: the same seed gives the same model bit for bit.
    #[arg(long, default_value_t = YarnFailure::default().seed)]
    seed: u64,
    /// Rate law of the failure strain, ε_f(ε̇) = ε_f (1 + C ln(ε̇/ε̇₀)) above ε̇₀: C (0: none).
    #[arg(long, default_value_t = YarnFailure::default().rate_coefficient)]
    failure_rate_coefficient: f64,
    /// The rate law's reference rate ε̇₀ [1/s].
    #[arg(long, default_value_t = YarnFailure::default().reference_rate)]
    failure_reference_rate: f64,
    /// Length of yarn [m] a chain's strain is averaged over before it is compared with
    /// the failure strain (chains only) [default: 0, each element's own].
    #[arg(long)]
    failure_length: Option<f64>,
    #[command(flatten)]
    ballistic: BallisticArgs,
    /// The armour test's backing (NIJ Standard-0101.06): `clay` lays the pack on a block
    /// of Roma Plastilina No. 1 (the --clay-* flags; `weft-weave clay-drop` calibrates
    /// it), its edges then free; weft-simulate then writes bfs.parquet (the crater
    /// against time) and the summary's `bfs` (its deepest point at the end).
    #[arg(long, value_enum, default_value_t = Backing::None)]
    backing: Backing,
    #[command(flatten)]
    clay: super::clay::ClayArgs,
}

/// What the pack lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Backing {
    /// Nothing: the pack in air, held at its edges.
    None,
    /// A block of the calibrated clay.
    Clay,
}

impl WovenBandArgs {
    pub fn params(&self) -> WovenBandParams {
        let (pr, run) = (&self.projectile, &self.run);
        WovenBandParams {
            yarns: self.yarns,
            quarter: !self.patch.full,
            spacing: self.patch.spacing,
            width: self.width,
            thickness: self.thickness,
            crimp_amplitude: self.crimp_amplitude,
            per_spacing: self.per_spacing,
            across: self.across,
            yarn_model: self.yarn_model,
            modulus: self.modulus,
            transverse_modulus: self.transverse_modulus,
            shear_modulus: self.shear_modulus,
            density: self.density,
            friction: self.friction,
            tension_field: self.tension_field,
            layers: self.layers,
            layer_gap: self.layer_gap,
            edge: self.edge,
            projectile_shape: pr.projectile_shape,
            projectile_radius: pr.projectile_radius,
            projectile_mass: pr.projectile_mass,
            projectile_velocity: pr.projectile_velocity,
            projectile_friction: pr.projectile_friction,
            end_time: run.end_time,
            output_interval: run.output_interval,
            dt_safety: run.dt_safety,
            surround: self.membrane_length.map(|length| Surround {
                length,
                growth: self.membrane_growth,
                // The yarn-level patch's membrane keeps ν = 0 (no flag).
                membrane: self
                    .surround
                    .params(Surround::default().membrane.poisson_ratio),
            }),
            failure: YarnFailure {
                strain: self.failure_strain,
                weibull_modulus: self.weibull_modulus,
                gauge_length: self.weibull_gauge_length,
                per: self.strength_per,
                seed: self.seed,
                rate_coefficient: self.failure_rate_coefficient,
                reference_rate: self.failure_reference_rate,
                delay: self.ballistic.failure_delay,
                contact_damping: self.ballistic.projectile_contact_damping,
                length: self.failure_length,
            },
            stop_on_outcome: self.ballistic.stop_on_outcome,
            // (Checked in `weave`, before the model is built.)
            bullet: pr
                .bullet
                .params(self.backing == Backing::Clay)
                .ok()
                .flatten(),
            backing: (self.backing == Backing::Clay).then(|| clay::Backing {
                clay: self
                    .clay
                    .clay(clay::PACK_HOURGLASS, Some(clay::PACK_EROSION)),
                block: self.clay.block(clay::ClayBlock::under_pack()),
            }),
        }
    }

    pub fn weave(&self) -> anyhow::Result<()> {
        self.projectile
            .bullet
            .params(self.backing == Backing::Clay)?;
        // The --clay-* flags are checked with or without --backing clay: a bad one is a
        // mistake either way.
        self.clay
            .clay(clay::PACK_HOURGLASS, Some(clay::PACK_EROSION))
            .check()?;
        self.clay.block(clay::ClayBlock::under_pack()).check()?;
        let out = &self.out.out;
        let m = super::weave(&Spec::Woven(self.params()), out)?;
        eprintln!(
            "weft-weave woven: {} nodes, {} elements, {} contact definitions -> {}",
            m.num_nodes(),
            m.num_elements(),
            m.contacts.len(),
            out.display()
        );
        Ok(())
    }
}

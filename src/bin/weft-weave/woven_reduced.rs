//! `weft-weave woven-reduced`'s flags: the reduced model's own (its yarns, links and
//! surround), and the groups it shares with `woven` ([`super::fabric`]).

use weft::generate::reduced_failure::ReducedFailure;
use weft::generate::weave::Spec;
use weft::generate::woven_reduced::{Interface, PretensionStart, WovenParams};

use super::fabric::{BallisticArgs, OutArgs, PatchArgs, ProjectileArgs, RunArgs, SurroundArgs};

/// Axes of the reduced model's links.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum LinkAxes {
    /// Global x, y, z.
    Global,
    /// The crossing's frame: warp direction, weft direction, their normal.
    Local,
    /// The crossing's frame, its ends points of the two yarns that slide along them when
    /// the link slips (the yarns slide across each other).
    Sliding,
}

impl LinkAxes {
    /// The axes of `p`'s links.
    fn of(p: &WovenParams) -> LinkAxes {
        match (p.local_frame, p.sliding) {
            (_, true) => LinkAxes::Sliding,
            (true, false) => LinkAxes::Local,
            (false, false) => LinkAxes::Global,
        }
    }
}

#[derive(clap::Args)]
pub struct WovenArgs {
    #[command(flatten)]
    pub out: OutArgs,
    /// Yarns per side of the full patch (even).
    #[arg(long, default_value_t = WovenParams::default().yarns)]
    yarns: usize,
    #[command(flatten)]
    patch: PatchArgs<WovenParams>,
    /// Yarn Young's modulus [Pa] (aramid).
    #[arg(long, default_value_t = WovenParams::default().yarn_modulus)]
    yarn_modulus: f64,
    /// Yarn density [kg/m³].
    #[arg(long, default_value_t = WovenParams::default().yarn_density)]
    yarn_density: f64,
    /// Yarn cross-section area [m²] (190 g/m² fabric at 1 mm spacing).
    #[arg(long, default_value_t = WovenParams::default().yarn_area)]
    yarn_area: f64,
    /// Let yarns carry compression too.
    #[arg(long)]
    compressible_yarns: bool,
    /// Yarn pretension as an initial strain ε₀ [–] (the yarns start with the force E·A·ε₀;
    /// see --pretension-start).
    #[arg(long, default_value_t = WovenParams::default().pretension_strain)]
    pretension_strain: f64,
    /// How a pretensioned model starts: `balanced` (the membrane around carries the same
    /// tension per width, N = E·A·ε₀/p, as an initial stress N/s: in equilibrium at t = 0
    /// for straight yarns), `relaxed` (balanced, then the crimped crossings settled by
    /// dynamic relaxation and written as initial displacements: for --crimp > 0) or
    /// `unbalanced` (only the yarns pre-strained: the membrane is pulled in and rings;
    /// the behaviour before the fix).
    #[arg(long, value_enum, default_value_t = WovenParams::default().pretension_start)]
    pretension_start: PretensionStart,
    /// Crimp: z offset of warp and weft at the crossings, ± [m].
    #[arg(long, default_value_t = WovenParams::default().crimp)]
    crimp: f64,
    /// Link stiffness k_x = k_y [N/m] (the paper's fitted 3.8661·10³ N/mm).
    #[arg(long, default_value_t = WovenParams::default().k_xy)]
    k_xy: f64,
    /// Link stiffness k_z [N/m] (the paper's fitted 5.2448·10⁶ N/mm).
    #[arg(long, default_value_t = WovenParams::default().k_z)]
    k_z: f64,
    /// Link dashpots c_x = c_y [N·s/m].
    #[arg(long, default_value_t = WovenParams::default().c_xy)]
    c_xy: f64,
    /// Link dashpot c_z [N·s/m].
    #[arg(long, default_value_t = WovenParams::default().c_z)]
    c_z: f64,
    /// Link friction slider: tangential slip force [N] [default: none].
    #[arg(long)]
    slip_force: Option<f64>,
    /// Link Coulomb friction coefficient μ [–]: the tangential springs slip at μ·N, N the
    /// normal spring's compressive force (not with --slip-force) [default: none].
    #[arg(long)]
    link_friction: Option<f64>,
    /// Unilateral link normal: the normal spring (and dashpot) pushes the yarns apart and
    /// never pulls them together [default: two-way, as the paper's links].
    #[arg(long)]
    unilateral_links: bool,
    /// Link axes: `global` (x, y, z, as the paper's links), `local` (the crossing's two
    /// yarn directions and their normal, following the fabric as it tilts) or `sliding`
    /// (local, and the link's ends are points of the yarns that move along them when the
    /// link slips: the yarns slide across each other; give --link-friction or
    /// --slip-force).
    #[arg(long, value_enum, default_value_t = LinkAxes::of(&WovenParams::default()))]
    link_axes: LinkAxes,
    #[command(flatten)]
    surround: SurroundArgs,
    /// Membrane surround: Poisson's ratio ν [–].
    #[arg(long, default_value_t = WovenParams::default().surround.poisson_ratio, allow_hyphen_values = true)]
    membrane_poisson: f64,
    /// Side of the whole model [m].
    #[arg(long, default_value_t = WovenParams::default().length)]
    length: f64,
    /// Growth ratio of the membrane cells away from the patch.
    #[arg(long, default_value_t = WovenParams::default().growth)]
    growth: f64,
    /// Where the patch meets the membrane: `crossing` (on the last crossing line x = np,
    /// whose yarns are halved) or `band-ends` (as `woven --membrane-length`: the last
    /// crossing line a full yarn, the rods running on to the membrane at (n + ½)p; quarter
    /// only; for comparing with the yarn-level patch).
    #[arg(long, value_enum, default_value_t = WovenParams::default().interface)]
    interface: Interface,
    #[command(flatten)]
    projectile: ProjectileArgs<WovenParams>,
    #[command(flatten)]
    run: RunArgs<WovenParams>,
    /// Failure strain of the rods, their engineering axial strain (0: they never fail, as
    /// in the paper's §5). A rod spans a crossing spacing and runs straight, so the strain
    /// at which the reduced model perforates as the yarn-level patch does is fitted
    /// (`weft-fit --objective projectile --param yarns.eps_f,half_yarns.eps_f:…`); the
    /// yarn's own 0.036 is the trial value.
    #[arg(long, default_value_t = WovenParams::default().failure.strain)]
    failure_strain: f64,
    #[command(flatten)]
    ballistic: BallisticArgs,
}

impl WovenArgs {
    pub fn params(&self) -> WovenParams {
        let (pr, run) = (&self.projectile, &self.run);
        WovenParams {
            yarns: self.yarns,
            spacing: self.patch.spacing,
            yarn_modulus: self.yarn_modulus,
            yarn_density: self.yarn_density,
            yarn_area: self.yarn_area,
            tension_only: !self.compressible_yarns,
            pretension_strain: self.pretension_strain,
            pretension_start: self.pretension_start,
            crimp: self.crimp,
            k_xy: self.k_xy,
            k_z: self.k_z,
            c_xy: self.c_xy,
            c_z: self.c_z,
            slip_force: self.slip_force,
            friction: self.link_friction,
            unilateral: self.unilateral_links,
            local_frame: self.link_axes == LinkAxes::Local,
            sliding: self.link_axes == LinkAxes::Sliding,
            surround: self.surround.params(self.membrane_poisson),
            length: self.length,
            growth: self.growth,
            quarter: !self.patch.full,
            interface: self.interface,
            projectile_shape: pr.projectile_shape,
            projectile_radius: pr.projectile_radius,
            projectile_mass: pr.projectile_mass,
            projectile_velocity: pr.projectile_velocity,
            projectile_friction: pr.projectile_friction,
            end_time: run.end_time,
            output_interval: run.output_interval,
            dt_safety: run.dt_safety,
            // (Checked in `weave`, before the model is built.)
            bullet: pr.bullet.params(false).ok().flatten(),
            failure: ReducedFailure {
                strain: self.failure_strain,
                delay: self.ballistic.failure_delay,
                contact_damping: self.ballistic.projectile_contact_damping,
            },
            stop_on_outcome: self.ballistic.stop_on_outcome,
        }
    }

    pub fn weave(&self) -> anyhow::Result<()> {
        self.projectile.bullet.params(false)?;
        let p = self.params();
        let out = &self.out.out;
        let m = super::weave(&Spec::WovenReduced(p.clone()), out)?;
        let mp = p.membrane();
        eprintln!(
            "weft-weave woven-reduced: {} nodes, {} elements, {} ties; membrane surround ρs = {:.4e} kg/m² ({:.3} × the patch's 2ρA/p = {:.4e}), E = {:.3e} Pa, G = {:.3e} Pa, s = {:.3e} m -> {}",
            m.num_nodes(),
            m.num_elements(),
            m.ties.len(),
            mp.density * mp.thickness,
            mp.density * mp.thickness / p.patch_surface_density(),
            p.patch_surface_density(),
            mp.youngs_modulus,
            mp.shear_modulus,
            mp.thickness,
            out.display()
        );
        Ok(())
    }
}

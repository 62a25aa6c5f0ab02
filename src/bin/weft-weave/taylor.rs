//! `weft-weave taylor`'s flags.

use std::path::PathBuf;

use weft::generate::metals::Metal;
use weft::generate::taylor::TaylorParams;
use weft::generate::weave::Spec;

#[derive(clap::Args)]
pub struct TaylorArgs {
    /// Output model folder (replaced atomically if it exists).
    #[arg(long)]
    out: PathBuf,
    /// Rod length L [m].
    #[arg(long, default_value_t = TaylorParams::default().length)]
    length: f64,
    /// Rod diameter D [m].
    #[arg(long, default_value_t = TaylorParams::default().diameter)]
    diameter: f64,
    /// Impact velocity U [m/s].
    #[arg(long, default_value_t = TaylorParams::default().velocity)]
    velocity: f64,
    /// The rod's metal, with its Johnson–Cook constants (docs/theory.md, "Solid elements").
    #[arg(long, value_enum, default_value_t = TaylorParams::default().material)]
    material: Metal,
    /// J2 perfect plasticity at this yield stress [Pa] (the metal's density and
    /// elasticity), instead of Johnson–Cook: the material of Taylor's 1-D theory.
    #[arg(long)]
    yield_stress: Option<f64>,
    /// Cells from the axis to the rim (even, ≥ 2): the mesh density.
    #[arg(long, default_value_t = TaylorParams::default().radial)]
    radial: usize,
    /// Layers along the rod [default: cells as long as they are wide].
    #[arg(long)]
    axial: Option<usize>,
    /// Hourglass coefficient Q_hg (LS-DYNA's default 0.1).
    #[arg(long, default_value_t = TaylorParams::default().hourglass)]
    hourglass: f64,
    /// Coulomb friction between the rod and the wall.
    #[arg(long, default_value_t = TaylorParams::default().wall_friction)]
    wall_friction: f64,
    /// Simulated time [s] [default: 0.6·L/U].
    #[arg(long)]
    end_time: Option<f64>,
    /// Output interval [s] [default: end time / 100].
    #[arg(long)]
    output_interval: Option<f64>,
}

impl TaylorArgs {
    pub fn params(&self) -> TaylorParams {
        TaylorParams {
            length: self.length,
            diameter: self.diameter,
            velocity: self.velocity,
            material: self.material,
            yield_stress: self.yield_stress,
            radial: self.radial,
            axial: self.axial,
            hourglass: self.hourglass,
            wall_friction: self.wall_friction,
            end_time: self.end_time,
            output_interval: self.output_interval,
        }
    }

    pub fn weave(&self) -> anyhow::Result<()> {
        let p = self.params();
        let m = super::weave(&Spec::Taylor(p.clone()), &self.out)?;
        eprintln!(
            "weft-weave taylor: {} nodes, {} hexahedra ({} layers), {} at {} m/s -> {}",
            m.num_nodes(),
            m.num_elements(),
            p.layers(),
            p.material.name(),
            p.velocity,
            self.out.display()
        );
        Ok(())
    }
}

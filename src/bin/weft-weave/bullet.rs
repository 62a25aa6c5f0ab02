//! The deformable bullet's flags, flattened into the projectile's group that `woven` and
//! `woven-reduced` share ([`super::fabric::ProjectileArgs`]).

use weft::generate::bullet::{BulletKind, BulletParams};
use weft::generate::metals::Metal;

/// Rigid projectile or deformable bullet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Projectile {
    /// A rigid shape (--projectile-shape).
    Rigid,
    /// A bullet of hexahedra with Johnson–Cook metals (--bullet, --bullet-material).
    Deformable,
}

#[derive(clap::Args)]
pub struct BulletArgs {
    /// The projectile: a rigid shape, or a deformable 9 mm round-nose bullet of
    /// hexahedra (its diameter 2 × --projectile-radius, its mass --projectile-mass; docs/
    /// theory.md, "The deformable bullet") [default: deformable on the armour test's
    /// clay (woven --backing clay), rigid otherwise].
    #[arg(long, value_enum)]
    projectile: Option<Projectile>,
    /// The deformable bullet: homogeneous (`lead`, the paper's) or a full metal jacket
    /// (`fmj`: a core in a jacket) [default: fmj on the armour test's clay, the
    /// standard's 9 mm FMJ RN; lead otherwise].
    #[arg(long, value_enum)]
    bullet: Option<BulletKind>,
    /// The bullet's metal (the core's for fmj).
    #[arg(long, value_enum, default_value_t = BulletParams::default().core)]
    bullet_material: Metal,
    /// The fmj bullet's jacket metal.
    #[arg(long, value_enum, default_value_t = BulletParams::default().jacket)]
    bullet_jacket: Metal,
    /// Cells from the bullet's axis to its rim (even, ≥ 2).
    #[arg(long, default_value_t = BulletParams::default().radial)]
    bullet_radial: usize,
    /// Erode a bullet hexahedron at this equivalent plastic strain [default: never].
    #[arg(long)]
    bullet_erosion_strain: Option<f64>,
}

impl BulletArgs {
    /// The bullet's parameters when deformable (diameter and mass are set from the
    /// projectile's flags by the generator); its flags are checked either way, so that a
    /// bad value is not silently ignored with a rigid projectile. `armour`: the pack is
    /// on the armour test's clay, where the defaults are the standard's FMJ.
    pub fn params(&self, armour: bool) -> weft::error::Result<Option<BulletParams>> {
        let (projectile, kind) = if armour {
            (Projectile::Deformable, BulletKind::Fmj)
        } else {
            (Projectile::Rigid, BulletParams::default().kind)
        };
        let p = BulletParams {
            kind: self.bullet.unwrap_or(kind),
            core: self.bullet_material,
            jacket: self.bullet_jacket,
            radial: self.bullet_radial,
            erosion_plastic_strain: self.bullet_erosion_strain,
            ..Default::default()
        };
        weft::generate::bullet::check(&p)?;
        Ok((self.projectile.unwrap_or(projectile) == Projectile::Deformable).then_some(p))
    }
}

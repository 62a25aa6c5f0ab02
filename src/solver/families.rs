//! The solver's element families, in slot order: the one invocation of
//! [`families!`](crate::families) that generates [`Families`] (the vocabulary of a family
//! is in [`super::family`]). The order of the list is the order of the force slots, of
//! the masses' accumulation and of the sums.

use super::{beam, link, membrane, point_mass, sliding_link, solid, truss};

crate::families! {
    truss: truss::TrussGroup,
    link: link::LinkGroup,
    framed_link: link::FramedLinkGroup,
    sliding_link: sliding_link::SlidingLinkGroup,
    point_mass: point_mass::PointMassGroup,
    tri: membrane::MembraneGroup<3>,
    quad: membrane::MembraneGroup<4>,
    beam: beam::BeamGroup,
    hex: solid::hex::HexGroup,
}

//! Element families: one vocabulary for every kind of element, and the list of families
//! the solver iterates with static dispatch.
//!
//! A family (truss, link, point mass, membrane triangle, membrane quad, beam) owns its
//! elements as struct-of-arrays, builds them from the model, and walks the same phases
//! as every other family (after OpenRadioss' element groups):
//! - `build`: read its block of the model, add its lumped masses (and rotary inertia);
//! - `forces`: gather positions → kinematics → constitutive → internal force, written
//!   into the family's own force slots (one slot per element node), in parallel fixed
//!   chunks of [`CHUNK`] elements; the node update gathers the slots in a fixed order;
//! - `stiffness_sums`: its contribution to the nodal Gershgorin bound of the stable step
//!   (see [`super::stable`]) and `stiffness` for the report of the controlling element;
//! - `energies`: per-chunk partial sums (internal, damping, friction, hourglass).
//!
//! And, each with a default that does nothing, what only some families need of the time
//! loop: failure and erosion (`collect_failures`, `alive`, `eroded_energy`, the
//! per-element energies of `ballistic.parquet`'s layers), the stiffening a deformed
//! element adds to the stable step's rows (`add_stiffening`, and the variable step that
//! follows it, [`Family::VARIABLE_STEP`]), the path-dependent state the output samples
//! carry (`sample_states`), the faces a projectile strikes (`contact_faces`), and what a
//! family records once the step is set (`step_was_set`). The time loop, the stable step
//! and the output call them through [`Families`](super::Families) and never name a family.
//!
//! Adding a family is one file that implements [`Family`] and one line in
//! [`families!`](crate::families)' invocation in `solver/families.rs`. The order of that list
//! is the order of the force slots, of the masses' accumulation and of the sums, so it
//! is part of what makes results reproducible bit for bit.

use super::failure::{Erosion, Failure};
use super::rotations::Rotations;
use super::vec3::{Mat3, Vec3};
use crate::error::Result;
use crate::model::{ElementKind, Model};

/// Elements per parallel chunk. Fixed, so that chunked reductions do not depend on the
/// thread count; large enough (≈50 kB of element data) to amortise task overhead, small
/// enough that a 10⁴-element model splits evenly over two threads.
pub const CHUNK: usize = 1024;

/// What a family's build reads and adds to besides itself.
pub struct Build<'a> {
    pub model: &'a Model,
    /// Lumped nodal masses [kg], accumulated family by family in list order.
    pub mass: &'a mut Vec<f64>,
    /// Rotational nodes (created by the families whose nodes carry rotations).
    pub rot: &'a mut Rotations,
}

/// The state a force kernel reads.
pub struct ForceCtx<'a> {
    /// Positions x^n [m].
    pub x: &'a [Vec3],
    /// Half-step velocities v^{n−½} [m/s].
    pub v: &'a [Vec3],
    /// Orientations of the rotational nodes.
    pub rot_r: &'a [Mat3],
    /// Δt^{n−½} [s].
    pub dt_prev: f64,
    /// Where this step stands in the subcycle of the slow elements
    /// ([`crate::solver::subcycle`]); [`SlowStep::NONE`] when nothing is subcycled.
    pub slow: SlowStep,
}

/// The slow elements' part of a step ([`crate::solver::subcycle`]): whether they are
/// updated at this step (a sample of the slow step), the time since their last update
/// T^{k−½} [s] (their Δt), and the weight of their forces, (T^{k−½} + T^{k+½}) /
/// (Δt^{n−½} + Δt^{n+½}), which makes the node update's kick of this step the slow
/// step's impulse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlowStep {
    pub sample: bool,
    pub dt: f64,
    pub weight: f64,
    /// The weight of an element that leaves the slow step at this sample (fast from the
    /// next step: its impulse closes the slow interval and opens a fast step),
    /// (T^{k−½} + Δt^{n+½}) / (Δt^{n−½} + Δt^{n+½}).
    pub close: f64,
}

impl SlowStep {
    /// No subcycle: every element is updated every step.
    pub const NONE: SlowStep = SlowStep {
        sample: true,
        dt: 0.0,
        weight: 1.0,
        close: 1.0,
    };
}

/// The slow elements a family chose for the subcycle ([`Family::choose_subcycle`]).
#[derive(Debug, Clone, Default)]
pub struct SlowChoice {
    /// Fast steps per slow step.
    pub ratio: u64,
    /// How many elements are slow.
    pub elements: usize,
    /// The nodes of the slow elements (ascending).
    pub nodes: Vec<usize>,
}

/// What the stable-step bound reads.
pub struct StiffCtx<'a> {
    /// Bit d set when translation d of the node is fixed.
    pub fixed: &'a [u8],
    /// Lumped masses [kg].
    pub mass: &'a [f64],
    /// Rotary inertia of each rotational node [kg·m²].
    pub rot_j: &'a [f64],
}

/// The element that stiffened a node most, as the stable step's checks keep it: the
/// stiffness it added, its id, three numbers that say how it deformed, and its family's
/// [`Family::describe_stiffening`], which puts them in words.
#[derive(Debug, Clone, Copy)]
pub struct Stiffened {
    /// The stiffness added to the node's row [N/m].
    pub added: f64,
    pub id: i64,
    pub q: [f64; 3],
    pub describe: fn(i64, [f64; 3], f64) -> (String, Option<String>),
}

impl Stiffened {
    /// What happened to the element, and a hint of its family's own when it has one.
    pub fn describe(&self, dt_safety: f64) -> (String, Option<String>) {
        (self.describe)(self.id, self.q, dt_safety)
    }
}

/// The path-dependent state of one element's integration point, as the output samples
/// carry it (σ [Pa] in Voigt order [xx, yy, zz, xy, yz, zx], ε_p, T [K]).
pub type StateValues = [f64; 8];

/// Per-chunk partial sums of the element energies [J]:
/// `[internal, damping, friction, hourglass]`.
pub type EnergyPartial = [f64; 4];

/// Summation groups of the energy ledger: each group sums its families' chunk partials
/// in list order; the totals are (Line + Membrane) + Beam. The grouping is the order
/// the sums have always been taken in, kept so that results stay bit-identical.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EnergyGroup {
    /// One-dimensional elements: trusses and links (and point masses, which store none).
    Line = 0,
    /// Membrane triangles and quads.
    Membrane = 1,
    /// Beams (energy taken before the rotations advance).
    Beam = 2,
    /// Solids (hexahedra), added last: a model without them sums as before, bit for bit.
    Solid = 3,
}

/// One element family (see the module docs for the phases).
pub trait Family: Sized + Send + Sync {
    const KIND: ElementKind;
    /// Force slots (nodes) per element.
    const SLOTS: usize;
    const GROUP: EnergyGroup;
    fn build(b: &mut Build) -> Result<Self>;
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Element id (the `id` column of its table).
    fn id(&self, e: usize) -> i64;
    /// Node indices of element e, one per force slot.
    fn slot_nodes(&self, e: usize) -> &[u32];
    /// A representative stiffness [N/m] (or damping [N·s/m]) for naming the element
    /// that controls the step.
    fn stiffness(&self, e: usize) -> f64;
    /// Internal forces exerted on the element nodes into `fe` (`SLOTS` per element).
    /// Families with state (link sliders, dissipated energies) advance it here: call
    /// once per step.
    fn forces(&mut self, ctx: &ForceCtx, fe: &mut [Vec3]);
    /// Adds the family's row sums S_i, C_i (and the rotational rows) of the stable-step
    /// bound.
    fn stiffness_sums(&self, ctx: &StiffCtx, s: &mut [f64], c: &mut [f64], rot_row: &mut [f64]);
    /// Per-chunk energy partials at the positions in `ctx` (eroded elements hold none).
    fn energies(&mut self, ctx: &ForceCtx) -> &[EnergyPartial];
    /// The failure laws and fates of a family whose elements can fail (trusses, links,
    /// membranes): the four methods below read them. `None` (the default): nothing fails.
    fn erosion(&self) -> Option<&Erosion> {
        None
    }
    fn erosion_mut(&mut self) -> Option<&mut Erosion> {
        None
    }
    /// Moves the failures of the last force pass, in element order, to `out` (a family
    /// whose elements cannot fail has none).
    fn collect_failures(&mut self, out: &mut Vec<Failure>) {
        if let Some(er) = self.erosion_mut() {
            er.collect(out);
        }
    }
    /// Whether element e is still in the model (not eroded).
    fn alive(&self, e: usize) -> bool {
        self.erosion().is_none_or(|er| er.alive(e))
    }
    /// The strain energy its failures have taken so far [J].
    fn eroded_energy(&self) -> f64 {
        self.erosion().map_or(0.0, Erosion::eroded_energy)
    }
    /// Whether any of its elements can fail.
    fn can_fail(&self) -> bool {
        self.erosion().is_some_and(Erosion::active)
    }
    /// Element e's stored energy at `x` (strain and hourglass) [J]; 0 once it has failed
    /// (families whose energies `ballistic.parquet` reports by layer: trusses, membranes).
    fn element_energy(&self, _x: &[Vec3], _e: usize) -> f64 {
        0.0
    }
    /// What element e's failures have taken [J].
    fn element_eroded(&self, _e: usize) -> f64 {
        0.0
    }
    /// Whether `ballistic.parquet` reports its elements' energies by layer
    /// ([`Family::element_energy`], [`Family::element_eroded`]).
    const BY_LAYER: bool = false;
    /// Adds to each node's stable-step row the stiffness its deformed elements have gained
    /// since the step was set (at positions `x`), and keeps in `most` the element that
    /// added most to the node.
    fn add_stiffening(&self, _x: &[Vec3], _extra: &mut [f64], _most: &mut [Option<Stiffened>]) {}
    /// Whether the variable step (`Analysis::variable_time_step`) follows this family's
    /// stiffening: its nodes' step is recomputed from it as the run goes (crushed solids).
    const VARIABLE_STEP: bool = false;
    /// What the deformation `q` of element `id` (its [`Stiffened`] record) means, for the
    /// message that stops a run, and a hint of its own when it has one (`dt_safety`: the
    /// analysis' safety factor). The default reads `q` as membrane Green strains.
    fn describe_stiffening(id: i64, q: [f64; 3], _dt_safety: f64) -> (String, Option<String>) {
        (
            format!(
                "{} `{id}` has stretched to a Green strain of [{:.3}, {:.3}, {:.3}] (E₁₁, E₂₂, 2E₁₂)",
                Self::KIND.name(),
                q[0],
                q[1],
                q[2]
            ),
            None,
        )
    }
    /// Chooses the elements whose state [`Family::sample_states`] reports (indices into
    /// the family, which are rows of its element table); families without a
    /// path-dependent state ignore it.
    fn set_state_output(&mut self, _elements: &[u32]) {}
    /// At an output sample, the state at tⁿ of the chosen elements, in their order,
    /// appended to `rows`.
    fn sample_states(&self, _rows: &mut Vec<StateValues>) {}
    /// A family whose nodes carry rotations (beams): per element the indices of its two
    /// rotational nodes, and its end moments (two per element [N·m], written by
    /// `forces`), which the rotational nodes' update gathers. One family at most.
    fn rotational(&self) -> Option<(&[[u32; 2]], &[Vec3])> {
        None
    }
    /// The faces a rigid projectile strikes: each element's nodes and its mass [kg].
    fn contact_faces<'a>(&'a self, _out: &mut Vec<(&'a [u32], f64)>) {}
    /// Once the step is set: the reference positions `x_ref`, the nodal masses it was set
    /// with and the fixed directions (the membranes' collapse criterion keeps what it
    /// compares with).
    fn step_was_set(&mut self, _x_ref: &[Vec3], _mass: &[f64], _fixed: &[u8]) {}
    /// A family that can subcycle ([`crate::solver::subcycle`]; the hexahedra) chooses its
    /// slow elements from each node's stable step `node_dt` [s] (with the margin of the
    /// fast step) and the fast step `dt`, and from then on updates them at the slow
    /// samples of [`ForceCtx::slow`] only. `None` (the default): nothing subcycles.
    fn choose_subcycle(&mut self, _node_dt: &[f64], _dt: f64, _x: &[Vec3]) -> Option<SlowChoice> {
        None
    }
    /// Per model node, whether only the family's slow elements act on it (between slow
    /// samples no force does: the node update skips its slots); `None` without slow
    /// elements.
    fn drift_nodes(&self) -> Option<&[bool]> {
        None
    }
    /// The slow elements' forces per node at the last slow sample [N], unweighted
    /// ([`crate::solver::subcycle`]); `None` without slow elements.
    fn slow_forces(&self) -> Option<&[Vec3]> {
        None
    }
    /// The stiffening of the slow elements at `x` (as [`Family::add_stiffening`], which
    /// leaves them out: the slow step follows them, not the fast one).
    fn add_slow_stiffening(
        &self,
        _x: &[Vec3],
        _extra: &mut [f64],
        _most: &mut [Option<Stiffened>],
    ) {
    }
}

/// Totals of the energy ledger's groups (see [`EnergyGroup`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct EnergySums {
    pub groups: [EnergyPartial; 4],
}

impl EnergySums {
    pub fn add(&mut self, group: EnergyGroup, parts: &[EnergyPartial]) {
        let g = &mut self.groups[group as usize];
        for p in parts {
            for c in 0..4 {
                g[c] += p[c];
            }
        }
    }
    /// Component c of the total: ((Line + Membrane) + Beam) + Solid.
    pub fn total(&self, c: usize) -> f64 {
        ((self.groups[0][c] + self.groups[1][c]) + self.groups[2][c]) + self.groups[3][c]
    }
}

/// Declares the solver's element families, in slot order: generates the `Families`
/// struct (one field per family) and its loops over all of them.
#[macro_export]
macro_rules! families {
    ($($field:ident : $ty:ty),* $(,)?) => {
        /// Every element family of a model, in slot order.
        #[derive(Debug, Clone)]
        pub struct Families {
            $(pub $field: $ty,)*
        }

        impl Families {
            pub fn build(b: &mut $crate::solver::family::Build) -> $crate::error::Result<Self> {
                Ok(Families { $($field: <$ty as $crate::solver::family::Family>::build(b)?,)* })
            }
            /// Total number of elements.
            pub fn len(&self) -> usize {
                0 $(+ $crate::solver::family::Family::len(&self.$field))*
            }
            /// Elements that take a force update (all but point masses): the count the
            /// element-updates rate is of.
            pub fn updated_elements(&self) -> usize {
                0 $(+ if <$ty as $crate::solver::family::Family>::KIND
                    == $crate::model::ElementKind::PointMass
                {
                    0
                } else {
                    $crate::solver::family::Family::len(&self.$field)
                })*
            }
            pub fn is_empty(&self) -> bool {
                self.len() == 0
            }
            /// Total number of force slots.
            pub fn slots(&self) -> usize {
                0 $(+ <$ty as $crate::solver::family::Family>::SLOTS
                    * $crate::solver::family::Family::len(&self.$field))*
            }
            /// Node of every force slot, in slot order.
            pub fn slot_nodes(&self) -> Vec<u32> {
                let mut v = Vec::with_capacity(self.slots());
                $(
                    for e in 0..$crate::solver::family::Family::len(&self.$field) {
                        v.extend_from_slice($crate::solver::family::Family::slot_nodes(&self.$field, e));
                    }
                )*
                v
            }
            /// The element of a force slot: kind, id, stiffness.
            pub fn slot_element(&self, mut slot: usize) -> Option<($crate::model::ElementKind, i64, f64)> {
                $(
                    let n = <$ty as $crate::solver::family::Family>::SLOTS
                        * $crate::solver::family::Family::len(&self.$field);
                    if slot < n {
                        let e = slot / <$ty as $crate::solver::family::Family>::SLOTS.max(1);
                        return Some((
                            <$ty as $crate::solver::family::Family>::KIND,
                            $crate::solver::family::Family::id(&self.$field, e),
                            $crate::solver::family::Family::stiffness(&self.$field, e),
                        ));
                    }
                    slot -= n;
                )*
                let _ = slot;
                None
            }
            /// Internal forces of every family into its slots of `fe`.
            pub fn forces(&mut self, ctx: &$crate::solver::family::ForceCtx, fe: &mut [[f64; 3]]) {
                let mut rest = fe;
                $(
                    let n = <$ty as $crate::solver::family::Family>::SLOTS
                        * $crate::solver::family::Family::len(&self.$field);
                    let (mine, r) = std::mem::take(&mut rest).split_at_mut(n);
                    rest = r;
                    if n > 0 {
                        $crate::solver::family::Family::forces(&mut self.$field, ctx, mine);
                    }
                )*
                let _ = rest;
            }
            pub fn stiffness_sums(
                &self,
                ctx: &$crate::solver::family::StiffCtx,
                s: &mut [f64],
                c: &mut [f64],
                rot_row: &mut [f64],
            ) {
                $($crate::solver::family::Family::stiffness_sums(&self.$field, ctx, s, c, rot_row);)*
            }
            /// The failures of the last force pass, family by family in list order, each
            /// in element order, with the element's id and nodes (its force slots').
            /// `scratch` is reused between calls.
            pub fn collect_failures(
                &mut self,
                scratch: &mut Vec<$crate::solver::failure::Failure>,
                out: &mut Vec<$crate::solver::failure::Collected>,
            ) {
                $(
                    scratch.clear();
                    $crate::solver::family::Family::collect_failures(&mut self.$field, scratch);
                    for f in scratch.iter() {
                        let nodes = $crate::solver::family::Family::slot_nodes(&self.$field, f.element);
                        out.push($crate::solver::failure::Collected {
                            failure: *f,
                            id: $crate::solver::family::Family::id(&self.$field, f.element),
                            nodes: nodes.to_vec(),
                        });
                    }
                )*
            }
            /// Whether any element of any family can fail.
            pub fn can_fail(&self) -> bool {
                false $(|| $crate::solver::family::Family::can_fail(&self.$field))*
            }
            /// The strain energy every failure has taken so far [J], in list order.
            pub fn eroded_energy(&self) -> f64 {
                0.0 $(+ $crate::solver::family::Family::eroded_energy(&self.$field))*
            }
            /// Every family's stiffening at `x` ([`Family::add_stiffening`]), in list order;
            /// with `variable_only`, that of the families the variable step follows.
            pub fn add_stiffening(
                &self,
                x: &[$crate::solver::vec3::Vec3],
                extra: &mut [f64],
                most: &mut [Option<$crate::solver::family::Stiffened>],
                variable_only: bool,
            ) {
                $(
                    if !variable_only || <$ty as $crate::solver::family::Family>::VARIABLE_STEP {
                        $crate::solver::family::Family::add_stiffening(&self.$field, x, extra, most);
                    }
                )*
            }
            /// The first family that subcycles ([`Family::choose_subcycle`]), in list order.
            pub fn choose_subcycle(
                &mut self,
                node_dt: &[f64],
                dt: f64,
                x: &[$crate::solver::vec3::Vec3],
            ) -> Option<$crate::solver::family::SlowChoice> {
                $(
                    if let Some(c) = $crate::solver::family::Family::choose_subcycle(&mut self.$field, node_dt, dt, x) {
                        return Some(c);
                    }
                )*
                None
            }
            /// The drifting nodes of the first family that has slow elements.
            pub fn drift_nodes(&self) -> Option<&[bool]> {
                $(
                    if let Some(d) = $crate::solver::family::Family::drift_nodes(&self.$field) {
                        return Some(d);
                    }
                )*
                None
            }
            /// The slow elements' forces per node of the first family that has some.
            pub fn slow_forces(&self) -> Option<&[$crate::solver::vec3::Vec3]> {
                $(
                    if let Some(f) = $crate::solver::family::Family::slow_forces(&self.$field) {
                        return Some(f);
                    }
                )*
                None
            }
            /// Every family's slow elements' stiffening ([`Family::add_slow_stiffening`]).
            pub fn add_slow_stiffening(
                &self,
                x: &[$crate::solver::vec3::Vec3],
                extra: &mut [f64],
                most: &mut [Option<$crate::solver::family::Stiffened>],
            ) {
                $($crate::solver::family::Family::add_slow_stiffening(&self.$field, x, extra, most);)*
            }
            /// Marks the nodes of the families the variable step follows.
            pub fn mark_variable_step_nodes(&self, mark: &mut [bool]) {
                $(
                    if <$ty as $crate::solver::family::Family>::VARIABLE_STEP {
                        for e in 0..$crate::solver::family::Family::len(&self.$field) {
                            for &n in $crate::solver::family::Family::slot_nodes(&self.$field, e) {
                                mark[n as usize] = true;
                            }
                        }
                    }
                )*
            }
            /// Chooses the elements of kind `kind` whose state the output samples carry.
            pub fn set_state_output(&mut self, kind: $crate::model::ElementKind, elements: &[u32]) {
                $(
                    if <$ty as $crate::solver::family::Family>::KIND == kind {
                        $crate::solver::family::Family::set_state_output(&mut self.$field, elements);
                    }
                )*
            }
            /// The chosen elements' states at an output sample, family by family.
            pub fn sample_states(&self, rows: &mut Vec<$crate::solver::family::StateValues>) {
                rows.clear();
                $($crate::solver::family::Family::sample_states(&self.$field, rows);)*
            }
            /// The rotational nodes' slots and the end moments of the family whose nodes
            /// carry rotations ([`Family::rotational`]), or none.
            pub fn rotational(&self) -> (&[[u32; 2]], &[$crate::solver::vec3::Vec3]) {
                $(
                    if let Some(r) = $crate::solver::family::Family::rotational(&self.$field) {
                        return r;
                    }
                )*
                (&[], &[])
            }
            /// Every family's faces a projectile strikes, in list order.
            pub fn contact_faces(&self) -> Vec<(&[u32], f64)> {
                let mut out = vec![];
                $($crate::solver::family::Family::contact_faces(&self.$field, &mut out);)*
                out
            }
            /// Tells every family the step is set ([`Family::step_was_set`]).
            pub fn step_was_set(&mut self, x_ref: &[$crate::solver::vec3::Vec3], mass: &[f64], fixed: &[u8]) {
                $($crate::solver::family::Family::step_was_set(&mut self.$field, x_ref, mass, fixed);)*
            }
            /// `f(kind, element, stored energy, eroded energy)` for every element of the
            /// families that `ballistic.parquet` reports by layer, in list order.
            pub fn for_layer_energies(
                &self,
                xn: &[$crate::solver::vec3::Vec3],
                mut f: impl FnMut($crate::model::ElementKind, usize, &dyn Fn() -> (f64, f64)),
            ) {
                $(
                    if <$ty as $crate::solver::family::Family>::BY_LAYER {
                        let fam = &self.$field;
                        for e in 0..$crate::solver::family::Family::len(fam) {
                            f(<$ty as $crate::solver::family::Family>::KIND, e, &|| {
                                (
                                    $crate::solver::family::Family::element_energy(fam, xn, e),
                                    $crate::solver::family::Family::element_eroded(fam, e),
                                )
                            });
                        }
                    }
                )*
            }
            /// Element energies summed by group (see `EnergyGroup`).
            pub fn energies(&mut self, ctx: &$crate::solver::family::ForceCtx) -> $crate::solver::family::EnergySums {
                let mut sums = $crate::solver::family::EnergySums::default();
                $(
                    if !$crate::solver::family::Family::is_empty(&self.$field) {
                        let p = $crate::solver::family::Family::energies(&mut self.$field, ctx);
                        sums.add(<$ty as $crate::solver::family::Family>::GROUP, p);
                    }
                )*
                sums
            }
        }
    };
}

/// Per-element slices that travel together through the chunked loops of
/// [`for_chunks_of`]: [`Per`] (one slice, `per` values per element) and tuples of them.
/// Each chunk holds the same `CHUNK` elements of every slice, so a family's kernel sees
/// its elements' force slots, state, fates and work side by side.
pub trait Chunked: Send + Sized {
    type Item: Send;
    type Serial: Iterator<Item = Self::Item>;
    type Parallel: rayon::iter::IndexedParallelIterator<Item = Self::Item>;
    fn serial(self) -> Self::Serial;
    fn parallel(self) -> Self::Parallel;
}

/// A per-element slice with `.1` values per element (a family's force slots: `SLOTS`;
/// its per-element state: 1), split into chunks of `CHUNK` elements.
pub struct Per<'a, T>(pub &'a mut [T], pub usize);

impl<'a, T: Send> Chunked for Per<'a, T> {
    type Item = &'a mut [T];
    type Serial = std::slice::ChunksMut<'a, T>;
    type Parallel = rayon::slice::ChunksMut<'a, T>;
    fn serial(self) -> Self::Serial {
        self.0.chunks_mut(self.1 * CHUNK)
    }
    fn parallel(self) -> Self::Parallel {
        use rayon::prelude::*;
        self.0.par_chunks_mut(self.1 * CHUNK)
    }
}

/// One value per chunk (a chunk's partial sums), beside the chunks of [`Per`] slices.
pub struct Each<'a, T>(pub &'a mut [T]);

impl<'a, T: Send> Chunked for Each<'a, T> {
    type Item = &'a mut T;
    type Serial = std::slice::IterMut<'a, T>;
    type Parallel = rayon::slice::IterMut<'a, T>;
    fn serial(self) -> Self::Serial {
        self.0.iter_mut()
    }
    fn parallel(self) -> Self::Parallel {
        use rayon::prelude::*;
        self.0.par_iter_mut()
    }
}

impl<A: Chunked, B: Chunked> Chunked for (A, B) {
    type Item = (A::Item, B::Item);
    type Serial = std::iter::Zip<A::Serial, B::Serial>;
    type Parallel = rayon::iter::Zip<A::Parallel, B::Parallel>;
    fn serial(self) -> Self::Serial {
        self.0.serial().zip(self.1.serial())
    }
    fn parallel(self) -> Self::Parallel {
        use rayon::prelude::*;
        self.0.parallel().zip(self.1.parallel())
    }
}

/// Runs `body(chunk index, chunks)` over the `CHUNK`-element chunks of the per-element
/// slices `slices` ([`Chunked`]: a [`Per`], or pairs of them, nested for more), in
/// parallel when there are more than `CHUNK` elements (`n_elements`), in order on the
/// calling thread otherwise. Each chunk is written by one call only, so the results do
/// not depend on the thread count.
#[inline]
pub fn for_chunks_of<S, F>(n_elements: usize, slices: S, body: F)
where
    S: Chunked,
    F: Fn(usize, S::Item) + Send + Sync,
{
    use rayon::prelude::*;
    if n_elements <= CHUNK {
        slices.serial().enumerate().for_each(|(ci, c)| body(ci, c));
    } else {
        slices
            .parallel()
            .enumerate()
            .for_each(|(ci, c)| body(ci, c));
    }
}

/// Runs `body(chunk index, chunk)` over `CHUNK`-element chunks of `out` (`per` slots
/// per element): [`for_chunks_of`] with one slice.
#[inline]
pub fn for_chunks<T: Send, F>(out: &mut [T], per: usize, n_elements: usize, body: F)
where
    F: Fn(usize, &mut [T]) + Send + Sync,
{
    for_chunks_of(n_elements, Per(out, per), body);
}

/// Fills `partials` (one per `CHUNK` elements) with `f(element range)`, in parallel.
#[inline]
pub fn chunk_partials<F>(partials: &mut Vec<EnergyPartial>, n_elements: usize, f: F)
where
    F: Fn(std::ops::Range<usize>) -> EnergyPartial + Send + Sync,
{
    use rayon::prelude::*;
    partials.resize(n_elements.div_ceil(CHUNK), [0.0; 4]);
    partials
        .par_iter_mut()
        .enumerate()
        .with_min_len(4)
        .for_each(|(ci, out)| *out = f(ci * CHUNK..((ci + 1) * CHUNK).min(n_elements)));
}

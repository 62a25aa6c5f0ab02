//! Surrogates of a fitted dependence x → y (the paper's §4: girder parameters x = {b_g,
//! N_g} to membrane parameters y = {G_m, s_m, ρ_m}), the stage behind `weft-surrogate`:
//!
//! - **Regression:** least squares on the monomials of total degree ≤ p of the scaled
//!   inputs (log, then mapped to [−1, 1]), solved by nalgebra's SVD; p chosen by k-fold
//!   cross-validation on the training and validation rows.
//! - **Network:** the paper's two-layer network (Fig. 6a): inputs and outputs mapped to
//!   [−1, 1] (MATLAB's `mapminmax`), one hidden layer of n₁ neurons, tanh ("tansig") or
//!   logistic ("logsig"), linear output; trained by Levenberg–Marquardt (MATLAB's
//!   `trainlm`, what the paper's "back-propagation" ran; here the `levenberg-marquardt`
//!   crate) with early stopping on the validation rows (stop after 6 epochs without a
//!   better validation error, keep the best weights, as `trainlm` does); several random
//!   initialisations.
//! - **Search:** n₁ × activation × restarts, the test MSE of each (the paper's Fig. 6b);
//!   the network of smallest validation MSE is kept.
//!
//! MSEs are in normalised output units (each output mapped to [−1, 1] by its range over
//! the training rows, averaged over outputs), as the toolbox reports them.
//!
//! Deterministic: the split and every initialisation come from the seed; experiments run
//! in parallel but each is sequential and they are collected in order, so the results do
//! not depend on the thread count.
//!
//! Files: `scale` (the maps to [−1, 1]), `regression`, `network` (and its LM training),
//! `numerics` (the seeded stream, the MSE), `rows` (x and y from a table), `train` (the
//! split, the search, the written tables), `file` (`surrogate.json`) and `predict`.

mod file;
mod network;
mod numerics;
mod predict;
mod regression;
mod rows;
mod scale;
mod train;

pub use file::{Surrogate, FORMAT};
pub use network::{train_network, Activation, Network, Trained, Training};
pub use numerics::{mse, permutation};
pub use predict::{predict, PredictConfig, PredictReport};
pub use regression::{fit_regression, monomials, Regression};
pub use scale::{Map, Scale};
pub use train::{train, Experiment, TrainConfig, TrainReport};

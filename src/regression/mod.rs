//! Regression engine: bivariate line fitting for allometry.
//!
//! Modelled on the R package smatr (Warton, Wright, Falster & Westoby 2006,
//! "Bivariate line-fitting methods for allometry", Biol. Rev. 81:259–291) and
//! lmodel2. Everything here is pure numerics on slices: the caller chooses the
//! data, the transform (or [`fit_power_law`] takes log10 itself) and the level.
//!
//! - [`fit_line`]: OLS (faer QR), MA and SMA with smatr's `line.cis` intervals.
//! - [`fit_power_law`]: y = A·x^b via log10–log10 lines.
//! - [`slope_test`], [`elev_test`], [`slope_com`], [`elev_com`]: smatr's tests.
//! - [`ols_diagnostics`], [`leave_one_out`], [`studentized_outliers`]: influence of single
//!   points.
//! - [`bootstrap_line`]: seeded case-resampling percentile intervals.
//! - [`predict_ols`], [`back_transform`], [`inverse_predict_ols`]: prediction.
//! - [`spearman`]: rank correlation.
//!
//! This module depends only on external crates, never on other `crate::` modules.
#![warn(missing_docs)]

mod bootstrap;
mod diagnostics;
pub mod dist;
mod error;
mod hypothesis;
mod line;
mod moments;
mod power_law;
mod predict;
mod rank;

pub use bootstrap::{
    BcaInterval, BootstrapConfig, BootstrapResult, bca_interval, bootstrap_line,
    jackknife_influence, jackknife_line, quantile,
};
pub use diagnostics::{
    LeaveOneOut, OlsDiagnostics, leave_one_out, ols_diagnostics, studentized_outliers,
};
pub use error::RegressionError;
pub use hypothesis::{
    CommonSlopeTest, ElevationComparison, ElevationTest, Group, GroupElevation, GroupLine,
    SlopeTest, TestKind, elev_com, elev_test, slope_com, slope_test,
};
pub use line::{Interval, LineFit, Method, fit_line};
pub use moments::Moments;
pub use power_law::{PowerLawFit, fit_power_law, log10_checked};
pub use predict::{
    BackTransformedPrediction, BiasCorrection, CentreKind, InversePrediction, OlsPrediction,
    back_transform, inverse_predict_ols, predict_ols, predict_power_law,
};
pub use rank::spearman;

//! The fitted model against the measurements, and where it fails.
//!
//! [`compare`] takes the measured shots (`bouncelab_fit::MeasuredShot`) and the model's simulations of them
//! (from each shot's measured start, sampled at its frame times, as the fit does) and gives, per shot, the
//! residual series (measured − what the camera would see of the simulated ball) split by the simulated
//! phase at each frame (flight in, compression, restitution, flight out) and by component (tangential x,
//! normal y, and spin when the shot carries it), RMS and reduced χ² per phase and component against the
//! tracking σ, and the output errors (v_out, COR, μ) when the shot carries measured outputs.
//! [`diagnose`] then locates the failure: which phase/component holds most of χ², and which per-shot
//! errors trend with the conditions (impact speed, incline, drop height, surface), by ordinary least
//! squares and one-way ANOVA with Student t / F p-values, each significant trend said in one plain sentence.
//! The design choice: everything is computed from plain data (shots + simulations), so the same code serves
//! any model, the fit's own [`Problem`](bouncelab_fit::Problem) ([`compare_problem`]) or a user's.

mod csv_out;
mod error;
mod residuals;
mod trends;

pub use csv_out::{COMPARISON_COLUMNS, write_comparison_csv};
pub use error::CompareError;
pub use residuals::{
    Comparison, Component, ImpactPhase, OutputErrors, PhaseStats, ResidualPoint, ShotComparison, ShotExtras, SpinFrame,
    compare, compare_problem, compare_shot,
};
pub use trends::{Against, DiagnoseOptions, FailureReport, PhaseShare, Quantity, Trend, diagnose};

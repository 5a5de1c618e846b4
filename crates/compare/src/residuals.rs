//! Residual series per shot, split by phase and component, with RMS, reduced χ² and output errors.

use crate::CompareError;
use bouncelab_fit::{MeasuredOutputs, MeasuredShot, Problem};
use bouncelab_model::{Impact, Phase, Simulation};
use serde::{Deserialize, Serialize};

/// Two times closer than this are the same frame, s.
const SAME_TIME_S: f64 = 1e-9;
/// A measured outgoing speed component smaller than this has no meaningful % error, m/s.
const MIN_SPEED_FOR_PCT: f64 = 0.01;

/// The phase of the impact a frame belongs to (the simulation's phase at the frame's time).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ImpactPhase {
    /// Before touch.
    FlightIn,
    /// From touch to maximum compression.
    Compression,
    /// From maximum compression to separation.
    Restitution,
    /// After separation.
    FlightOut,
}

impl ImpactPhase {
    /// Every phase, in time order.
    pub const ALL: [ImpactPhase; 4] = [
        ImpactPhase::FlightIn,
        ImpactPhase::Compression,
        ImpactPhase::Restitution,
        ImpactPhase::FlightOut,
    ];

    /// Snake-case name, as in `comparison.csv`.
    pub fn name(self) -> &'static str {
        match self {
            ImpactPhase::FlightIn => "flight_in",
            ImpactPhase::Compression => "compression",
            ImpactPhase::Restitution => "restitution",
            ImpactPhase::FlightOut => "flight_out",
        }
    }

    /// Words for sentences ("flight in").
    pub fn words(self) -> &'static str {
        match self {
            ImpactPhase::FlightIn => "flight in",
            ImpactPhase::Compression => "compression",
            ImpactPhase::Restitution => "restitution",
            ImpactPhase::FlightOut => "flight out",
        }
    }
}

/// A component of the residual.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Component {
    /// Along the surface (x, down-slope), m.
    Tangential,
    /// Along the surface normal (y), m.
    Normal,
    /// Spin ω, rad/s (only for shots that carry measured spin).
    Spin,
}

impl Component {
    /// Every component.
    pub const ALL: [Component; 3] = [Component::Tangential, Component::Normal, Component::Spin];

    /// Snake-case name, as in `comparison.csv`.
    pub fn name(self) -> &'static str {
        match self {
            Component::Tangential => "tangential",
            Component::Normal => "normal",
            Component::Spin => "spin",
        }
    }

    /// Unit of the component's residuals ("m" or "rad/s").
    pub fn unit(self) -> &'static str {
        match self {
            Component::Spin => "rad/s",
            _ => "m",
        }
    }
}

/// A measured spin at one of the shot's frame times.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpinFrame {
    /// Time, s (must be one of the shot's frame times).
    pub t_s: f64,
    /// Measured spin, rad/s, counter-clockwise positive.
    pub omega_rad_s: f64,
    /// Its standard error, rad/s (> 0).
    pub sigma_rad_s: f64,
}

/// Evidence a shot carries besides its frames; every field is optional (the default has none).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ShotExtras {
    /// Drop height from `clips.csv`, m.
    pub drop_height_m: Option<f64>,
    /// Measured contact time, s.
    pub contact_time_s: Option<f64>,
    /// Camera roll from the surface line's tilt in the image, degrees.
    pub camera_roll_deg: Option<f64>,
    /// The camera roll's standard error, degrees, if known.
    #[serde(default)]
    pub camera_roll_se_deg: Option<f64>,
    /// Measured spin at some of the frame times.
    pub spin: Vec<SpinFrame>,
}

/// One frame's residual: measured − simulated (what the camera would see of the simulated ball).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ResidualPoint {
    /// Time, s.
    pub t_s: f64,
    /// Phase of the simulation at this time.
    pub phase: ImpactPhase,
    /// Tangential residual `x_m − x_sim`, m.
    pub dx_m: f64,
    /// Normal residual `y_m − y_sim`, m.
    pub dy_m: f64,
    /// Tracking σ of each coordinate, m.
    pub sigma_m: f64,
    /// Spin residual `ω_m − ω_sim`, rad/s, when spin was measured at this frame.
    pub d_omega_rad_s: Option<f64>,
    /// σ of the measured spin, rad/s.
    pub sigma_omega_rad_s: Option<f64>,
}

/// Goodness of fit of one phase and component (of one shot, or of all shots).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PhaseStats {
    /// The phase.
    pub phase: ImpactPhase,
    /// The component.
    pub component: Component,
    /// RMS of the residuals, m (rad/s for [`Component::Spin`]).
    pub rms_m: f64,
    /// Σ (residual/σ)².
    pub chi2: f64,
    /// χ² / n (no parameters are subtracted per phase).
    pub chi2_red: f64,
    /// Number of residuals.
    pub n: usize,
}

/// Output errors of one shot, all as measured − predicted.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OutputErrors {
    /// Outgoing tangential velocity, `(meas − pred)/|meas|`, %; `None` when |meas| < 0.01 m/s.
    pub v_out_t_pct: Option<f64>,
    /// Outgoing normal velocity, `(meas − pred)/|meas|`, %; `None` when |meas| < 0.01 m/s.
    pub v_out_n_pct: Option<f64>,
    /// COR, `(meas − pred)/meas`, %.
    pub cor_pct: f64,
    /// COR, `meas − pred` (dimensionless).
    pub cor_abs: f64,
    /// Effective friction μ, `meas − pred` (absolute: μ can be near 0).
    pub mu_abs: f64,
    /// Measured COR.
    pub cor_measured: f64,
    /// Predicted COR.
    pub cor_predicted: f64,
    /// Measured μ.
    pub mu_measured: f64,
    /// Predicted μ.
    pub mu_predicted: f64,
    /// Measured outgoing velocity (tangential, normal), m/s.
    pub v_out_measured: [f64; 2],
    /// Predicted outgoing velocity at separation (tangential, normal), m/s.
    pub v_out_predicted: [f64; 2],
}

/// The model against one shot.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShotComparison {
    /// Shot (clip) name.
    pub shot: String,
    /// Surface.
    pub surface: String,
    /// Incline, degrees.
    pub incline_deg: f64,
    /// Impact speed |v_n,in| at touch (the measured start carried to the surface by the simulation), m/s.
    pub impact_speed_m_s: f64,
    /// Drop height, m, if known.
    pub drop_height_m: Option<f64>,
    /// Camera roll from the surface line, degrees, if known.
    pub camera_roll_deg: Option<f64>,
    /// Its standard error, degrees, if known.
    #[serde(default)]
    pub camera_roll_se_deg: Option<f64>,
    /// Contact time, measured − predicted, ms, if measured.
    pub contact_time_error_ms: Option<f64>,
    /// One point per frame.
    pub residuals: Vec<ResidualPoint>,
    /// Per phase and component that has residuals (phase order, then tangential, normal, spin).
    pub by_phase: Vec<PhaseStats>,
    /// Output errors, when the shot carries measured outputs.
    pub output_errors: Option<OutputErrors>,
    /// RMS of the position residuals (x and y together), m.
    pub rms_m: f64,
    /// The shot's χ² (positions and spin).
    pub chi2: f64,
    /// Number of residuals (2 per frame + spin frames).
    pub n: usize,
}

/// The model against every shot.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// Per shot, in input order.
    pub shots: Vec<ShotComparison>,
    /// All shots together, per phase and component.
    pub overall: Vec<PhaseStats>,
    /// Total χ².
    pub chi2: f64,
    /// Total number of residuals.
    pub n_residuals: usize,
    /// Fitted parameters subtracted from the degrees of freedom (shared ones and per-shot nuisances).
    pub n_params: usize,
    /// The fit's reduced χ²: the positions' χ² over their residuals − `n_params` (spin residuals, which the
    /// fit does not minimise, are left out, so this is the number the fit reports).
    pub chi2_red_total: f64,
}

impl Comparison {
    /// The overall statistics of one phase and component.
    pub fn overall_of(&self, phase: ImpactPhase, component: Component) -> Option<&PhaseStats> {
        self.overall
            .iter()
            .find(|s| s.phase == phase && s.component == component)
    }
}

#[derive(Default, Clone, Copy)]
struct Acc {
    sq: f64,
    chi2: f64,
    n: usize,
}

impl Acc {
    fn add(&mut self, r: f64, sigma: f64) {
        self.sq += r * r;
        self.chi2 += (r / sigma) * (r / sigma);
        self.n += 1;
    }
    fn merge(&mut self, o: &Acc) {
        self.sq += o.sq;
        self.chi2 += o.chi2;
        self.n += o.n;
    }
}

type Table = [[Acc; 3]; 4];

fn stats_of(table: &Table) -> Vec<PhaseStats> {
    let mut out = Vec::new();
    for (i, phase) in ImpactPhase::ALL.iter().enumerate() {
        for (j, component) in Component::ALL.iter().enumerate() {
            let a = table[i][j];
            if a.n > 0 {
                out.push(PhaseStats {
                    phase: *phase,
                    component: *component,
                    rms_m: (a.sq / a.n as f64).sqrt(),
                    chi2: a.chi2,
                    chi2_red: a.chi2 / a.n as f64,
                    n: a.n,
                });
            }
        }
    }
    out
}

fn table_of(by_phase: &[PhaseStats]) -> Table {
    let mut t = Table::default();
    for s in by_phase {
        let (i, j) = (s.phase as usize, s.component as usize);
        t[i][j] = Acc {
            sq: s.rms_m * s.rms_m * s.n as f64,
            chi2: s.chi2,
            n: s.n,
        };
    }
    t
}

/// Compares one shot with its simulation (sampled at the shot's frame times, as
/// [`Problem::simulate`] returns it).
///
/// Fails naming the shot when the samples do not match the frames or a spin frame's time is not a frame
/// time.
pub fn compare_shot(
    shot: &MeasuredShot,
    sim: &Simulation,
    extras: &ShotExtras,
) -> Result<ShotComparison, CompareError> {
    let mismatch = |reason: String| CompareError::Mismatch {
        shot: shot.name.clone(),
        reason,
    };
    if sim.samples.len() != shot.frames.len() {
        return Err(mismatch(format!(
            "{} frames but {} simulated samples",
            shot.frames.len(),
            sim.samples.len()
        )));
    }
    let imp = &sim.impact;
    let (table, residuals) = residual_table(shot, sim, extras)?;
    let by_phase = stats_of(&table);
    let (mut sq, mut chi2, mut n, mut n_pos) = (0.0, 0.0, 0usize, 0usize);
    for s in &by_phase {
        chi2 += s.chi2;
        n += s.n;
        if s.component != Component::Spin {
            sq += s.rms_m * s.rms_m * s.n as f64;
            n_pos += s.n;
        }
    }
    let output_errors = shot.measured.map(|m| output_errors(&m, imp));
    Ok(ShotComparison {
        shot: shot.name.clone(),
        surface: shot.surface.clone(),
        incline_deg: shot.incline_rad.to_degrees(),
        impact_speed_m_s: imp.state_in.vy.abs(),
        drop_height_m: extras.drop_height_m,
        camera_roll_deg: extras.camera_roll_deg,
        camera_roll_se_deg: extras.camera_roll_se_deg,
        contact_time_error_ms: extras.contact_time_s.map(|tc| (tc - imp.contact_time()) * 1e3),
        residuals,
        by_phase,
        output_errors,
        rms_m: if n_pos > 0 { (sq / n_pos as f64).sqrt() } else { 0.0 },
        chi2,
        n,
    })
}

/// Every frame's residual (measured − simulated) with its phase, summed per phase and component into a
/// table, and the spin residuals at the frames `extras` gives spin at. Fails naming the shot when a frame's
/// sample is at another time, a spin value is unusable or a spin time is not a frame time.
fn residual_table(
    shot: &MeasuredShot,
    sim: &Simulation,
    extras: &ShotExtras,
) -> Result<(Table, Vec<ResidualPoint>), CompareError> {
    let mismatch = |reason: String| CompareError::Mismatch {
        shot: shot.name.clone(),
        reason,
    };
    let imp = &sim.impact;
    let mut table = Table::default();
    let mut residuals = Vec::with_capacity(shot.frames.len());
    let mut spin = extras.spin.iter().peekable();
    for (k, (f, s)) in shot.frames.iter().zip(&sim.samples).enumerate() {
        if (f.t_s - s.t).abs() > SAME_TIME_S {
            return Err(mismatch(format!(
                "frame {k} is at t = {} s but its sample at t = {} s",
                f.t_s, s.t
            )));
        }
        let phase = match s.phase {
            Phase::Compression => ImpactPhase::Compression,
            Phase::Restitution => ImpactPhase::Restitution,
            Phase::Flight if s.t < imp.t_touch => ImpactPhase::FlightIn,
            Phase::Flight => ImpactPhase::FlightOut,
        };
        let (dx, dy) = (f.x_m - s.observed.x, f.y_m - s.observed.y);
        let row = &mut table[phase as usize];
        row[Component::Tangential as usize].add(dx, f.sigma_m);
        row[Component::Normal as usize].add(dy, f.sigma_m);
        let (mut d_omega, mut sigma_omega) = (None, None);
        if let Some(sp) = spin.peek()
            && (sp.t_s - f.t_s).abs() <= SAME_TIME_S
        {
            if !(sp.sigma_rad_s.is_finite() && sp.sigma_rad_s > 0.0 && sp.omega_rad_s.is_finite()) {
                return Err(mismatch(format!(
                    "spin at t = {} s has σ = {} rad/s or a non-finite value",
                    sp.t_s, sp.sigma_rad_s
                )));
            }
            let d = sp.omega_rad_s - s.observed.omega;
            row[Component::Spin as usize].add(d, sp.sigma_rad_s);
            (d_omega, sigma_omega) = (Some(d), Some(sp.sigma_rad_s));
            spin.next();
        }
        residuals.push(ResidualPoint {
            t_s: f.t_s,
            phase,
            dx_m: dx,
            dy_m: dy,
            sigma_m: f.sigma_m,
            d_omega_rad_s: d_omega,
            sigma_omega_rad_s: sigma_omega,
        });
    }
    if let Some(sp) = spin.next() {
        return Err(mismatch(format!(
            "spin at t = {} s is not at a frame time (spin frames must be frame times, in order)",
            sp.t_s
        )));
    }
    Ok((table, residuals))
}

/// The measured outputs `m` against the simulated impact's.
fn output_errors(m: &MeasuredOutputs, imp: &Impact) -> OutputErrors {
    let pred = [imp.state_out.vx, imp.state_out.vy];
    let pct =
        |k: usize| (m.v_out[k].abs() >= MIN_SPEED_FOR_PCT).then(|| (m.v_out[k] - pred[k]) / m.v_out[k].abs() * 100.0);
    OutputErrors {
        v_out_t_pct: pct(0),
        v_out_n_pct: pct(1),
        cor_pct: (m.cor - imp.restitution) / m.cor * 100.0,
        cor_abs: m.cor - imp.restitution,
        mu_abs: m.mu - imp.effective_friction,
        cor_measured: m.cor,
        cor_predicted: imp.restitution,
        mu_measured: m.mu,
        mu_predicted: imp.effective_friction,
        v_out_measured: m.v_out,
        v_out_predicted: pred,
    }
}

/// Compares every shot with its simulation; `extras` is empty (no extras) or one per shot; `n_params` is
/// the number of fitted parameters, subtracted from the degrees of freedom of the total reduced χ².
pub fn compare(
    shots: &[MeasuredShot],
    sims: &[Simulation],
    extras: &[ShotExtras],
    n_params: usize,
) -> Result<Comparison, CompareError> {
    if sims.len() != shots.len() {
        return Err(CompareError::CountMismatch {
            shots: shots.len(),
            other: sims.len(),
            what: "simulations",
        });
    }
    if !extras.is_empty() && extras.len() != shots.len() {
        return Err(CompareError::CountMismatch {
            shots: shots.len(),
            other: extras.len(),
            what: "extras",
        });
    }
    let none = ShotExtras::default();
    let per: Vec<ShotComparison> = shots
        .iter()
        .zip(sims)
        .enumerate()
        .map(|(i, (shot, sim))| compare_shot(shot, sim, extras.get(i).unwrap_or(&none)))
        .collect::<Result<_, _>>()?;
    let mut total = Table::default();
    for s in &per {
        let t = table_of(&s.by_phase);
        for (row, trow) in total.iter_mut().zip(&t) {
            for (a, b) in row.iter_mut().zip(trow) {
                a.merge(b);
            }
        }
    }
    let overall = stats_of(&total);
    let chi2: f64 = per.iter().map(|s| s.chi2).sum();
    let n_residuals: usize = per.iter().map(|s| s.n).sum();
    let positions = overall.iter().filter(|s| s.component != Component::Spin);
    let (chi2_pos, n_pos) = positions.fold((0.0, 0usize), |(c, n), s| (c + s.chi2, n + s.n));
    let dof = n_pos.saturating_sub(n_params);
    Ok(Comparison {
        shots: per,
        overall,
        chi2,
        n_residuals,
        n_params,
        chi2_red_total: if dof > 0 { chi2_pos / dof as f64 } else { f64::NAN },
    })
}

/// Simulates the problem's shots at `theta` (e.g. the fitted parameters) and compares them; the free
/// parameters and each shot's surface level (when the problem fits them) are subtracted from the degrees of
/// freedom, as the fit does.
pub fn compare_problem(problem: &Problem, theta: &[f64], extras: &[ShotExtras]) -> Result<Comparison, CompareError> {
    let sims = problem.simulate(theta)?;
    let n_params = problem.params().len() + problem.nuisance_per_shot() * problem.shots().len();
    compare(problem.shots(), &sims, extras, n_params)
}

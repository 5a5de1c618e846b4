//! `bouncelab analyze SESSION_DIR`: the whole chain over a session folder, incremental through the store.

use anyhow::Context;
use bouncelab_analyze::{Analysis, AnalyzeOptions, Progress, Stage, analyze};
use bouncelab_diagnose::Diagnosis;
use bouncelab_store::ClipFingerprint;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

#[derive(clap::Args)]
pub struct Args {
    /// Session folder (session.toml, clips.csv, one folder of frames per clip).
    pub session_dir: PathBuf,
    /// Output folder [default: bouncelab-results/<session folder name>].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Model file (model.toml) [default: the paper's model].
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Results store; results accumulate there across sessions [default: bouncelab.sqlite beside the output folder].
    #[arg(long)]
    pub store: Option<PathBuf>,
    /// Fingerprint frames by content instead of name, size and modification time (reads every frame).
    #[arg(long)]
    pub content_hash: bool,
    /// Skip the missing-effect search.
    #[arg(long)]
    pub no_diagnose: bool,
    /// Settings for every clip of the session (each beats clip.toml, camera headers and session.toml).
    #[command(flatten)]
    pub settings: super::settings::Overrides,
}

impl Args {
    /// Output folder and store path, defaults resolved.
    pub fn paths(&self) -> (PathBuf, PathBuf) {
        let name = self
            .session_dir
            .canonicalize()
            .ok()
            .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_else(|| "session".into());
        let out = self
            .out
            .clone()
            .unwrap_or_else(|| Path::new("bouncelab-results").join(name));
        let store = self.store.clone().unwrap_or_else(|| {
            out.parent()
                .filter(|p| !p.as_os_str().is_empty())
                .unwrap_or(Path::new("."))
                .join("bouncelab.sqlite")
        });
        (out, store)
    }
}

/// A bar per stage on a terminal (a live line of iterations and reduced χ² for the fit); one plain line per
/// stage otherwise.
pub struct StageBars {
    terminal: bool,
    bar: Mutex<Option<indicatif::ProgressBar>>,
}

impl StageBars {
    pub fn new() -> StageBars {
        StageBars {
            terminal: std::io::stderr().is_terminal(),
            bar: Mutex::new(None),
        }
    }
}

/// What a stage counts.
fn unit(stage: Stage) -> &'static str {
    match stage {
        Stage::Track => "shots",
        Stage::Diagnose => "models",
        _ => "steps",
    }
}

impl Progress for StageBars {
    fn start(&self, stage: Stage, total: u64) {
        if !self.terminal {
            return;
        }
        let bar = if stage == Stage::Fit {
            // The solver's iterations are not known in advance: a spinner with the latest iteration.
            let bar = indicatif::ProgressBar::new_spinner();
            bar.set_style(
                indicatif::ProgressStyle::with_template("{prefix:>9} {spinner} {msg} [{elapsed}]")
                    .expect("valid template"),
            );
            bar.set_prefix(stage.name());
            bar.set_message("starting");
            bar.enable_steady_tick(std::time::Duration::from_millis(120));
            bar
        } else if total > 0 {
            super::progress_bar(total, stage.name(), unit(stage))
        } else {
            return;
        };
        *self.bar.lock().expect("progress lock") = Some(bar);
    }
    fn advance(&self, _stage: Stage, n: u64) {
        if let Some(b) = self.bar.lock().expect("progress lock").as_ref() {
            b.inc(n);
        }
    }
    fn iteration(&self, _stage: Stage, iteration: usize, chi2_red: f64) {
        if let Some(b) = self.bar.lock().expect("progress lock").as_ref() {
            b.set_message(format!("iteration {iteration}, reduced χ² {chi2_red:.3}"));
        }
    }
    fn doing(&self, _stage: Stage, what: &str) {
        if let Some(b) = self.bar.lock().expect("progress lock").as_ref() {
            b.set_message(format!("fitting {what}"));
        }
    }
    fn finish(&self, stage: Stage, summary: &str) {
        if let Some(b) = self.bar.lock().expect("progress lock").take() {
            b.finish_and_clear();
        }
        eprintln!("{:>9}: {summary}", stage.name());
    }
    fn note(&self, message: &str) {
        let guard = self.bar.lock().expect("progress lock");
        match guard.as_ref() {
            Some(b) => b.println(format!("     note: {message}")),
            None => eprintln!("     note: {message}"),
        }
    }
}

/// Runs the analysis and prints its summary; an error if any shot failed (after writing everything else).
pub fn run(a: Args) -> anyhow::Result<()> {
    let analysis = run_quiet(&a)?;
    print_summary(&analysis);
    fail_on_failed_shots(&analysis)
}

/// Runs the analysis with progress on stderr and no summary.
pub fn run_quiet(a: &Args) -> anyhow::Result<Analysis> {
    let (out_dir, store_path) = a.paths();
    let options = AnalyzeOptions {
        out_dir,
        store_path,
        model_path: a.model.clone(),
        fingerprint: if a.content_hash {
            ClipFingerprint::Content
        } else {
            ClipFingerprint::Metadata
        },
        diagnose: !a.no_diagnose,
        clip_options: a.settings.clip_options(),
    };
    let progress = StageBars::new();
    analyze(&a.session_dir, &options, &progress).with_context(|| format!("analysing {}", a.session_dir.display()))
}

pub fn fail_on_failed_shots(analysis: &Analysis) -> anyhow::Result<()> {
    let failed = &analysis.measure.failed;
    if let Some((clip, message)) = failed.first() {
        anyhow::bail!(
            "{}: {} of {} shot(s) could not be measured (the others were analysed); first: {clip}: {message}",
            analysis.session_dir.display(),
            failed.len(),
            analysis.shots_listed
        );
    }
    Ok(())
}

/// The ranked candidates of a diagnosis (the first `limit`), with the four checks of each if `checks`.
pub fn print_candidates(d: &Diagnosis, limit: usize, checks: bool) {
    let legend = if checks {
        "  checks (BIC, held-out, parameter, material)"
    } else {
        ""
    };
    println!(
        "  {:<22} {:>10} {:>10} {:>10} {:>9} {:>9}{legend}",
        "candidate", "RMS µm", "held-out", "ΔBIC", "χ²_red", "explains"
    );
    let mark = |ok: bool| if ok { "✓" } else { "✗" };
    for c in d.candidates.iter().take(limit) {
        match &c.evidence {
            Some(e) => {
                let marks = if checks {
                    format!(
                        "  {} {} {} {}",
                        mark(c.checks.bic),
                        mark(c.checks.heldout),
                        mark(c.checks.parameter),
                        mark(c.checks.material)
                    )
                } else {
                    String::new()
                };
                println!(
                    "  {:<22} {:>10.1} {:>10.1} {:>10.1} {:>9.2} {:>9}{marks}",
                    c.effect,
                    e.error_after * 1e6,
                    e.heldout_error_after * 1e6,
                    e.delta_bic,
                    e.chi2_red_after,
                    if c.explains { "yes" } else { "no" }
                )
            }
            None => println!(
                "  {:<22} fit failed: {}",
                c.effect,
                c.failed.clone().unwrap_or_default()
            ),
        }
    }
}

pub fn print_summary(a: &Analysis) {
    println!(
        "{}: {} shot(s) listed, {} measured now, {} reused, {} failed",
        a.session_dir.display(),
        a.shots_listed,
        a.measure.measured.len(),
        a.measure.reused.len(),
        a.measure.failed.len()
    );
    println!(
        "model {}: position RMS {:.1} µm, reduced χ² {:.2}",
        a.model_origin,
        a.fit.rms_m * 1e6,
        a.fit.reduced_chi2
    );
    for p in &a.fit.parameters {
        // A length (a surface level) is a fraction of a millimetre: in µm, as residuals are.
        let (k, unit) = if p.param.ends_with("_m") {
            (1e6, " µm")
        } else {
            (1.0, "")
        };
        let ci = p
            .interval
            .map(|[lo, hi]| format!(" [{:.4}, {:.4}]", lo * k, hi * k))
            .unwrap_or_default();
        println!("  {:<28} {:>12.4}{unit}{ci}", p.name, p.value * k);
    }
    for sentence in &a.failure.sentences {
        println!("  {}", sentence.replace('`', ""));
    }
    for (clip, why) in &a.excluded {
        println!("left out of the fit: {clip}: {why}");
    }
    if let Ok(d) = &a.diagnosis {
        println!(
            "verdict: {} (the evidence: `bouncelab diagnose` or the report)",
            bouncelab_analyze::verdict_headline(d)
        );
        print_candidates(d, 5, false);
        if let Some(c) = d.candidates.first() {
            println!(
                "  (current model: RMS {:.1} µm, held-out {:.1} µm)",
                c.error_before * 1e6,
                c.heldout_error_before * 1e6
            );
        }
    }
    if let Some(b) = &a.before {
        println!(
            "before/after: position RMS {:.1} µm with {} → {:.1} µm now ({:.1}× lower); reduced χ² {:.2} → {:.2}",
            b.total_rms_m.0 * 1e6,
            b.before_model,
            b.total_rms_m.1 * 1e6,
            b.total_rms_m.0 / b.total_rms_m.1,
            b.reduced_chi2.0,
            b.reduced_chi2.1
        );
    }
    if a.history.len() > 1 {
        println!("model versions fitted to this session:");
        for h in &a.history {
            if let Some(f) = &h.latest {
                println!(
                    "  version {:<3} {:<28} RMS {:>7.1} µm  reduced χ² {:>8.2}  ({})",
                    h.version.id,
                    h.version.record.name,
                    f.record.rms_m * 1e6,
                    f.record.reduced_chi2,
                    f.created_at
                );
            }
        }
    }
    match &a.stats {
        Ok(st) => {
            println!("ANCOVA of COR (Type I, terms {}):", st.terms.join(", "));
            for r in &st.ancova.type1.terms {
                println!(
                    "  {:<10} F = {:>9.3}  p = {:.3e}",
                    r.source,
                    r.f.unwrap_or(f64::NAN),
                    r.p.unwrap_or(f64::NAN)
                );
            }
        }
        Err(reason) => println!("ANCOVA not computed: {reason}"),
    }
    for path in &a.outputs {
        println!("wrote {}", path.display());
    }
    let total: f64 = a.timings.iter().map(|(_, s)| s).sum();
    let parts: Vec<String> = a
        .timings
        .iter()
        .map(|(s, t)| format!("{} {t:.1} s", s.name()))
        .collect();
    println!("time {total:.1} s ({})", parts.join(", "));
}

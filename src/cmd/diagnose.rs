//! `bouncelab diagnose SESSION_DIR`: the analysis of `analyze` (incremental, so measured shots are
//! reused), printed as the missing-effect verdict with its evidence and the command that accepts it.

use super::analyze::{Args, fail_on_failed_shots, print_candidates, run_quiet};
use bouncelab_diagnose::VerdictKind;

pub fn run(mut a: Args) -> anyhow::Result<()> {
    a.no_diagnose = false;
    let analysis = run_quiet(&a)?;
    let d = match &analysis.diagnosis {
        Ok(d) => d,
        Err(why) => anyhow::bail!("{}: no diagnosis: {why}", a.session_dir.display()),
    };
    println!(
        "{}: {} shot(s), model {}",
        a.session_dir.display(),
        d.shots,
        analysis.model_origin
    );
    println!("verdict: {}", bouncelab_analyze::verdict_headline(d).replace('`', ""));
    println!("{}", d.verdict.sentence);
    println!();
    println!("where the current model's residual sits (share of χ², systematic part above the noise):");
    for p in d.signature.phases.iter().take(4) {
        println!(
            "  {:<28} {:>5.1} %  {:>7.1} µm",
            format!("{} {}", p.component.name(), p.phase.words()),
            100.0 * p.chi2_share,
            p.systematic_m * 1e6
        );
    }
    println!();
    print_candidates(d, d.candidates.len(), true);
    if let Some(c) = d.candidates.first() {
        println!(
            "  current model: RMS {:.1} µm, held-out {:.1} µm; noise {:.1} µm",
            c.error_before * 1e6,
            c.heldout_error_before * 1e6,
            d.noise.noise_m * 1e6
        );
    }
    let (out_dir, _) = a.paths();
    let diagnosis = out_dir.join("diagnosis.json");
    let model = a
        .model
        .as_ref()
        .map_or_else(|| "model.toml".to_string(), |m| m.display().to_string());
    match (d.verdict.kind, d.verdict.effect.as_deref()) {
        (VerdictKind::MissingEffect, Some(effect)) => println!(
            "\naccept it: bouncelab model add {effect} --model {model} --diagnosis {}",
            diagnosis.display()
        ),
        (VerdictKind::Ambiguous, Some(_)) => println!(
            "\nthe data cannot tell these apart; add one with: bouncelab model add EFFECT --model {model} --diagnosis {}",
            diagnosis.display()
        ),
        _ => {}
    }
    if let Some(p) = &d.proposal {
        println!(
            "\na formula term to try (add to {model}, then analyse again):\n{}",
            p.model_toml.trim_end()
        );
    }
    println!("wrote {}", diagnosis.display());
    fail_on_failed_shots(&analysis)
}

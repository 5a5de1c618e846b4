//! The small set of many looks that `cargo test` runs (preset `looks-smoke`, 6 shots, fixed seed): the
//! tracker and estimator against the renderer's truth. The full sweep is `cargo run --release --example
//! looks_accuracy` (`docs/accuracy.md`, "Many looks").

#[path = "common/looks.rs"]
mod looks;

#[test]
fn many_looks_are_measured_or_refused_with_a_reason_and_never_on_another_object() {
    let scenario = bouncelab_render::Scenario::preset("looks-smoke").unwrap();
    let tmp = tempfile::tempdir().unwrap();
    bouncelab_render::render(&scenario, tmp.path()).unwrap();
    let results = looks::evaluate(&tmp.path().join("session"), &tmp.path().join("truth"));
    println!("{}", looks::clip_table(&results));
    assert_eq!(results.len(), 6);
    for r in &results {
        // A frame reported as the ball is the ball, and on these clips its rim is read to within a pixel.
        assert_eq!(r.frames_off_ball, 0, "{}: frames on another object", r.clip);
        assert_eq!(r.frames_over_1px, 0, "{}: frames more than 1 px off", r.clip);
        // Every shot is either measured or says why not.
        match (&r.failure, &r.cor) {
            (Some(why), _) => assert!(!why.trim().is_empty(), "{}", r.clip),
            (None, Some(_)) => {}
            (None, None) => panic!("{}: neither measured nor refused", r.clip),
        }
    }
    // Measured shots: COR within 0.02 of the truth (ten times the target: a guard against the chain
    // breaking, not the accuracy claim), and the contact level within 3 standard errors of its own and
    // within 2 px (a ragged clay edge's line states ± 3–5 px, but the ball's touch, which it leans on,
    // a few tenths).
    let measured: Vec<_> = results.iter().filter(|r| r.failure.is_none()).collect();
    assert!(measured.len() >= 4, "only {} of 6 measured", measured.len());
    for r in measured {
        let (cor, _, truth) = r.cor.unwrap();
        assert!((cor - truth).abs() <= 0.02, "{}: COR {cor} vs {truth}", r.clip);
        let (_, level_err, sigma) = r.level.clone().unwrap();
        assert!(
            level_err.abs() <= (3.0 * sigma).min(2.0),
            "{}: level error {level_err} ± {sigma} px",
            r.clip
        );
    }
}

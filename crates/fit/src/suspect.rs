//! Which shots to keep out of a shared fit because their tracks, not the model, are at fault.

/// Least reduced χ² of a shot's worst flight fit for its track to be suspect: 9, a scatter of 3σ.
pub const SUSPECT_FLIGHT_CHI2_MIN: f64 = 9.0;

/// How far a shot's worst flight fit may scatter beyond the session's typical shot (× the median of the
/// shots' worst flight reduced χ²) before its track is suspect.
pub const SUSPECT_FLIGHT_FACTOR: f64 = 25.0;

/// Fewest shots with a finite flight χ² for the session's median to stand for its typical shot.
const SUSPECT_MIN_SHOTS: usize = 3;

/// Shots whose flight phases are not ballistic to within the tracking noise, far beyond the session's
/// other shots: `flight_chi2_red[i]` holds the reduced χ² of shot i's flight fits, and a shot is suspect
/// when its worst is not finite, or above [`SUSPECT_FLIGHT_CHI2_MIN`] and above [`SUSPECT_FLIGHT_FACTOR`] ×
/// the session's median. No contact model can fix a flight phase, so such a track (a seam or a shadow
/// followed for some frames) would only bend the shared fit; a missing flight effect (drag) raises every
/// shot's χ² and so the median with it. Returns each suspect shot's index with the reason, in a sentence;
/// none with fewer than three shots with a finite worst flight.
pub fn suspect_flights(flight_chi2_red: &[&[f64]]) -> Vec<(usize, String)> {
    let worst = |c: &[f64]| c.iter().cloned().fold(0.0, f64::max);
    let mut all: Vec<f64> = flight_chi2_red
        .iter()
        .map(|c| worst(c))
        .filter(|v| v.is_finite())
        .collect();
    if all.len() < SUSPECT_MIN_SHOTS {
        return Vec::new();
    }
    all.sort_by(f64::total_cmp);
    let median = all[all.len() / 2];
    flight_chi2_red
        .iter()
        .enumerate()
        .filter(|(_, c)| {
            let w = worst(c);
            !w.is_finite() || (w > SUSPECT_FLIGHT_CHI2_MIN && w > SUSPECT_FLIGHT_FACTOR * median)
        })
        .map(|(i, c)| {
            let w = worst(c);
            (
                i,
                format!(
                    "its flight fits scatter {:.0}× more than the tracker's σ (reduced χ² {:.1}; session median {:.2}): the track is suspect",
                    w.sqrt(),
                    w,
                    median
                ),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_flight_far_beyond_the_session_and_above_3_sigma_is_suspect() {
        let ok = [1.0, 1.2];
        let seam = [1.1, 40.0];
        let shots: Vec<&[f64]> = vec![&ok, &ok, &seam, &ok];
        let s = suspect_flights(&shots);
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].0, 2);
        assert!(s[0].1.contains("reduced χ² 40.0; session median 1.20"), "{}", s[0].1);
        // Drag raises every shot's χ²: 40 is then not 25× the median.
        let drag = [3.0, 4.0];
        let shots: Vec<&[f64]> = vec![&drag, &drag, &seam, &drag];
        assert!(suspect_flights(&shots).is_empty());
        // Below 9 (3σ) nothing is suspect, however quiet the others.
        let quiet = [0.01];
        let mild = [8.0];
        let shots: Vec<&[f64]> = vec![&quiet, &quiet, &mild, &quiet];
        assert!(suspect_flights(&shots).is_empty());
        // Too few shots to judge; a shot with no finite flight is suspect.
        assert!(suspect_flights(&[&ok, &seam]).is_empty());
        let lost = [f64::INFINITY];
        let shots: Vec<&[f64]> = vec![&ok, &ok, &ok, &lost];
        assert_eq!(suspect_flights(&shots)[0].0, 3);
    }
}

//! The contact measured again once the fit has found where the surface really is.

use crate::Estimate;

impl Estimate {
    /// Contact time, s, had the surface been `level_m` above the surface line found in the image: from the
    /// flight arcs' crossings of `radius_m + level_m` ([`Estimate::contact_at_level`]); `None` when the arcs
    /// do not give a positive, finite duration there.
    pub fn contact_time_at_level(&self, level_m: f64, radius_m: f64) -> Option<f64> {
        let (t0, t1) = self.contact_at_level(level_m, radius_m);
        Some(t1 - t0).filter(|d| d.is_finite() && *d > 0.0)
    }
}

//! [`Profile`], where a path-traced render's time goes: the time its threads spend in each
//! stage of the wavefront integrator, summed over threads.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// A stage of the wavefront path integrator, in the order a pass runs them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Camera rays and their samplers.
    Camera,
    /// Closest hits of every path's ray (the BVH).
    ClosestHits,
    /// The hit records: positions, normals and materials at the hits.
    HitRecords,
    /// Emission found by the rays, and paths that end.
    Emission,
    /// Light and BSDF samples one path at a time (every surface but diffuse and rough
    /// conductor ones, and every surface when one bounce is kept).
    Scattering,
    /// Light and BSDF samples of diffuse and rough conductor surfaces, sixteen paths at a
    /// time.
    SmoothLanes,
    /// Shadow rays (the BVH).
    ShadowRays,
    /// Adding up the unblocked light samples, and retiring the paths that ended.
    Gathering,
}

impl Stage {
    /// Every stage, in order.
    pub const ALL: [Stage; 8] = [
        Stage::Camera,
        Stage::ClosestHits,
        Stage::HitRecords,
        Stage::Emission,
        Stage::Scattering,
        Stage::SmoothLanes,
        Stage::ShadowRays,
        Stage::Gathering,
    ];

    /// A short name, as `prism render --stats` prints it.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Stage::Camera => "camera rays",
            Stage::ClosestHits => "closest hits",
            Stage::HitRecords => "hit records",
            Stage::Emission => "emission",
            Stage::Scattering => "scattering",
            Stage::SmoothLanes => "smooth lanes",
            Stage::ShadowRays => "shadow rays",
            Stage::Gathering => "gathering",
        }
    }
}

/// Time per [`Stage`], summed over the threads of a render (so up to the thread count
/// times the wall time). Empty for the integrators that do not run in stages.
#[derive(Debug, Default)]
pub struct Profile {
    nanos: [AtomicU64; Stage::ALL.len()],
}

impl Profile {
    /// Adds the times of `laps` (one thread's, for one tile).
    pub(crate) fn add(&self, laps: &Laps) {
        for (total, &t) in self.nanos.iter().zip(&laps.nanos) {
            total.fetch_add(t, Ordering::Relaxed);
        }
    }

    /// The time spent in `stage`.
    #[must_use]
    pub fn time(&self, stage: Stage) -> Duration {
        Duration::from_nanos(self.nanos[stage as usize].load(Ordering::Relaxed))
    }

    /// The time spent in all stages.
    #[must_use]
    pub fn total(&self) -> Duration {
        Stage::ALL.iter().map(|&s| self.time(s)).sum()
    }

    /// Each stage's share of [`Profile::total`] (none if nothing was timed).
    #[must_use]
    pub fn shares(&self) -> Option<Vec<(Stage, f64)>> {
        let total = self.total().as_secs_f64();
        (total > 0.0).then(|| {
            Stage::ALL
                .iter()
                .map(|&s| (s, self.time(s).as_secs_f64() / total))
                .collect()
        })
    }
}

/// One thread's stopwatch: the time since the last lap is charged to the stage that lap
/// names.
pub(crate) struct Laps {
    nanos: [u64; Stage::ALL.len()],
    last: Instant,
}

impl Laps {
    /// A stopwatch started now.
    pub(crate) fn start() -> Laps {
        Laps {
            nanos: [0; Stage::ALL.len()],
            last: Instant::now(),
        }
    }

    /// Charges the time since the last lap to `stage`.
    #[inline]
    pub(crate) fn lap(&mut self, stage: Stage) {
        let now = Instant::now();
        self.nanos[stage as usize] += now.duration_since(self.last).as_nanos() as u64;
        self.last = now;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Property: laps are charged to the stage they name, shares add up to one, and an
    /// untimed profile has no shares.
    #[test]
    fn laps_add_to_their_stages_and_shares_sum_to_one() {
        let p = Profile::default();
        assert!(p.shares().is_none());
        let mut laps = Laps::start();
        std::thread::sleep(Duration::from_millis(3));
        laps.lap(Stage::ShadowRays);
        laps.lap(Stage::Camera);
        p.add(&laps);
        p.add(&laps);
        assert!(p.time(Stage::ShadowRays) >= Duration::from_millis(6));
        assert!(p.time(Stage::Camera) < p.time(Stage::ShadowRays));
        assert_eq!(p.time(Stage::HitRecords), Duration::ZERO);
        let shares = p.shares().expect("timed");
        assert!((shares.iter().map(|s| s.1).sum::<f64>() - 1.0).abs() < 1e-9);
        assert_eq!(shares.len(), Stage::ALL.len());
    }
}

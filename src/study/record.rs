//! The record of one grid point.

/// What one grid point gave. Every field is a function of the spec and the point index
/// only (no shared state between points), so a point computes to the same bits in any
/// shard, on any thread.
#[derive(Debug, Clone, PartialEq)]
pub struct PointRecord {
    /// The point index `i = ix + nx·iy`.
    pub index: usize,
    /// `"ok"`, or what failed (the point's other fields hold what was computed before).
    pub status: String,
    /// The period in forcing periods (0: no period up to the maximum tested).
    pub period: usize,
    /// Impacts per forcing period, on all impact surfaces together (NaN if the run failed).
    pub impacts_per_period: f64,
    /// Impacts per forcing period on each impact surface, for a system with two or more
    /// (NaN if the run failed); empty for a system with one surface or none.
    pub impacts_per_surface: Vec<f64>,
    /// Top Lyapunov exponent (1/time unit; NaN if not recorded).
    pub tle: f64,
    /// Its standard error (NaN if not recorded).
    pub tle_spread: f64,
    /// Entropy index `q*` of the inter-impact intervals (NaN if not recorded or not
    /// defined, e.g. one interval value on a periodic orbit).
    pub q: f64,
    /// The last stroboscopic points, each the whole state (`(x, v)` for one degree of
    /// freedom, `(x1 … xN, v1 … vN)` for `N`; at most the spec's `record.poincare`, at
    /// least the period).
    pub sections: Vec<Vec<f64>>,
    /// The attractor fingerprint: the cells of the section tessellation visited by the
    /// recorded points (one integer per state component), sorted (see the
    /// [module docs](super)); empty on a grid without an initial-condition axis, where no
    /// two points share their parameters.
    pub cells: Vec<Vec<i64>>,
}

impl PointRecord {
    /// A point whose run failed (with no impacts per surface: a study of a system with two
    /// or more surfaces records NaN for each).
    pub fn failed(index: usize, message: String) -> Self {
        Self {
            index,
            status: message,
            period: 0,
            impacts_per_period: f64::NAN,
            impacts_per_surface: Vec::new(),
            tle: f64::NAN,
            tle_spread: f64::NAN,
            q: f64::NAN,
            sections: Vec::new(),
            cells: Vec::new(),
        }
    }

    /// Whether the point computed without failure.
    pub fn is_ok(&self) -> bool {
        self.status == "ok"
    }
}

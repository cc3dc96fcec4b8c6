//! Precision, recall and F-score at a distance threshold, as the Tanks and Temples evaluation
//! defines them: a distance counts when it is strictly below tau.

/// Default thresholds in percent of the ground-truth diagonal when none are given.
pub(crate) const DEFAULT_TAU_PERCENT: [f64; 3] = [0.5, 1.0, 2.0];

/// The thresholds of an evaluation, resolved once: each τ in ground-truth units, in the order
/// given (those in ground-truth units first, then those in percent of the diagonal).
#[derive(Debug, Clone, PartialEq)]
pub struct Thresholds {
    /// τ in ground-truth units.
    pub taus: Vec<f64>,
    /// The percents of the diagonal that were used (the defaults when nothing was given).
    pub percents_used: Vec<f64>,
    /// The ground-truth bounding-box diagonal they refer to.
    pub diagonal: f64,
}

impl Thresholds {
    /// Resolves `tau` (ground-truth units) and `percent_of_diagonal`; with neither,
    /// [`DEFAULT_TAU_PERCENT`].
    pub(crate) fn resolve(tau: &[f64], percent_of_diagonal: &[f64], diagonal: f64) -> Thresholds {
        let percents_used = if tau.is_empty() && percent_of_diagonal.is_empty() {
            DEFAULT_TAU_PERCENT.to_vec()
        } else {
            percent_of_diagonal.to_vec()
        };
        let mut taus = tau.to_vec();
        taus.extend(percents_used.iter().map(|p| p / 100.0 * diagonal));
        Thresholds {
            taus,
            percents_used,
            diagonal,
        }
    }

    /// τ in percent of the diagonal.
    pub(crate) fn percent_of_diagonal(&self, tau: f64) -> f64 {
        tau / self.diagonal * 100.0
    }
}

/// Share of `distances` strictly below `tau` (0 for an empty list).
pub(crate) fn share_below(distances: &[f64], tau: f64) -> f64 {
    if distances.is_empty() {
        return 0.0;
    }
    distances.iter().filter(|&&d| d < tau).count() as f64 / distances.len() as f64
}

/// Harmonic mean 2PR/(P+R), 0 when both are 0.
pub(crate) fn f_score(precision: f64, recall: f64) -> f64 {
    if precision + recall > 0.0 {
        2.0 * precision * recall / (precision + recall)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_counted() {
        let acc = [0.1, 0.2, 0.3, 0.4];
        let comp = [0.05, 0.5, 0.5, 0.5, 0.5];
        let p = share_below(&acc, 0.3); // 0.1, 0.2 → 2/4 (0.3 is not strictly below)
        let r = share_below(&comp, 0.3); // 1/5
        assert_eq!(p, 0.5);
        assert_eq!(r, 0.2);
        assert!((f_score(p, r) - 2.0 * 0.5 * 0.2 / 0.7).abs() < 1e-15);
        assert_eq!(f_score(0.0, 0.0), 0.0);
        assert_eq!(share_below(&[], 1.0), 0.0);
    }
}

//! Where the model's validation errors come from: Spearman rank correlation of each
//! validation run's worst component RMS error with the size of its tilt
//! (|theta_x| + |theta_z|) and of its offset (|x| + |z|).
//!
//! The paper model adds single-axis deviations and has no tilt-tilt or tilt-offset
//! coupling terms; if that is what limits it, the errors follow the tilt. A diagnostic for
//! `needle validate`, with no goal.

use serde::Serialize;

/// Rank correlations over the Table 2 and Latin-hypercube runs.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct ErrorTrend {
    /// Number of runs correlated.
    pub runs: usize,
    /// Spearman rank correlation of worst RMS % with |theta_x| + |theta_z| (deg), -1..=1.
    pub tilt_rho: f64,
    /// Spearman rank correlation of worst RMS % with |x| + |z| (mm), -1..=1.
    pub offset_rho: f64,
}

/// The trend of `worst_pct` over poses `[x_mm, z_mm, theta_x_deg, theta_z_deg]`; `None`
/// below 3 runs (no correlation to speak of) or when a column is constant.
pub fn trend(poses: &[[f64; 4]], worst_pct: &[f64]) -> Option<ErrorTrend> {
    if poses.len() != worst_pct.len() || poses.len() < 3 {
        return None;
    }
    let tilt: Vec<f64> = poses.iter().map(|p| p[2].abs() + p[3].abs()).collect();
    let offset: Vec<f64> = poses.iter().map(|p| p[0].abs() + p[1].abs()).collect();
    Some(ErrorTrend { runs: poses.len(), tilt_rho: spearman(&tilt, worst_pct)?, offset_rho: spearman(&offset, worst_pct)? })
}

/// Ranks 1..=n, ties given their mean rank.
fn ranks(v: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..v.len()).collect();
    order.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
    let mut r = vec![0.0; v.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j + 1 < order.len() && v[order[j + 1]] == v[order[i]] {
            j += 1;
        }
        let mean = (i + j) as f64 / 2.0 + 1.0;
        for &k in &order[i..=j] {
            r[k] = mean;
        }
        i = j + 1;
    }
    r
}

/// Spearman's rho: Pearson correlation of the ranks; `None` when a side is constant.
fn spearman(a: &[f64], b: &[f64]) -> Option<f64> {
    let (ra, rb) = (ranks(a), ranks(b));
    let n = ra.len() as f64;
    let (ma, mb) = (ra.iter().sum::<f64>() / n, rb.iter().sum::<f64>() / n);
    let cov: f64 = ra.iter().zip(&rb).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = ra.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = rb.iter().map(|y| (y - mb).powi(2)).sum();
    (va > 0.0 && vb > 0.0).then(|| cov / (va * vb).sqrt())
}

#[cfg(test)]
mod tests {
    use super::{ranks, spearman, trend};

    #[test]
    fn ranks_share_ties() {
        assert_eq!(ranks(&[3.0, 1.0, 3.0, 2.0]), vec![3.5, 1.0, 3.5, 2.0]);
    }

    #[test]
    fn spearman_of_monotone_reversed_and_constant() {
        let a = [1.0, 2.0, 5.0, 9.0];
        assert_eq!(spearman(&a, &[0.1, 0.2, 0.3, 8.0]), Some(1.0));
        assert_eq!(spearman(&a, &[4.0, 3.0, 2.0, 1.0]), Some(-1.0));
        assert_eq!(spearman(&a, &[1.0; 4]), None);
    }

    #[test]
    fn error_following_the_tilt_shows_in_tilt_rho() {
        // error grows with the tilt, offsets shuffled
        let poses = [[3.0, 0.0, 1.0, 0.0], [0.0, 1.0, 2.0, 2.0], [5.0, 5.0, 4.0, -3.0], [1.0, 0.0, -8.0, 6.0]];
        let t = trend(&poses, &[0.5, 1.0, 2.0, 4.0]);
        assert_eq!(t.map(|t| t.tilt_rho), Some(1.0));
        assert!(t.is_some_and(|t| t.offset_rho < 0.5), "{t:?}");
        assert_eq!(trend(&poses[..2], &[0.5, 1.0]), None, "two runs are too few");
    }
}

//! Gauss–Legendre quadrature, and Packard's uniform stepping, on [0, 1].

use std::sync::OnceLock;

/// Nodes and weights of an n-point rule on [0, 1]; the weights sum to 1.
#[derive(Clone, Debug, PartialEq)]
pub struct Rule {
    pub nodes: Vec<f64>,
    pub weights: Vec<f64>,
}

impl Rule {
    /// n-point Gauss–Legendre: the nodes are the roots x_i of the Legendre
    /// polynomial P_n, found by Newton's method from the estimate
    /// cos(π(i − 1/4)/(n + 1/2)) (Abramowitz and Stegun 22.16.6), with weights
    /// w_i = 2 / ((1 − x_i²) P_n'(x_i)²) on [−1, 1]; both are then mapped to
    /// [0, 1]. Exact for polynomials of degree 2n − 1. P_n and P_n' come from
    /// the three-term recurrence (k+1) P_{k+1} = (2k+1) x P_k − k P_{k−1}.
    pub fn gauss_legendre(n: usize) -> Rule {
        let n = n.max(1);
        let mut nodes = vec![0.0; n];
        let mut weights = vec![0.0; n];
        for i in 0..n.div_ceil(2) {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (p, d) = legendre(n, x);
                dp = d;
                let step = p / d;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            let (_, d) = legendre(n, x);
            if d.is_finite() {
                dp = d;
            }
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            // Roots come in ± pairs; map [−1, 1] to [0, 1].
            nodes[i] = 0.5 * (1.0 - x);
            nodes[n - 1 - i] = 0.5 * (1.0 + x);
            weights[i] = 0.5 * w;
            weights[n - 1 - i] = 0.5 * w;
        }
        Rule { nodes, weights }
    }

    /// Packard's uniform stepping: n equal cells, one point at the middle of
    /// each, weight 1/n (the midpoint rule).
    pub fn uniform(n: usize) -> Rule {
        let n = n.max(1);
        Rule { nodes: (0..n).map(|i| (i as f64 + 0.5) / n as f64).collect(), weights: vec![1.0 / n as f64; n] }
    }
}

/// P_n(x) and P_n'(x).
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    for k in 1..n {
        let p2 = ((2 * k + 1) as f64 * x * p1 - k as f64 * p0) / (k + 1) as f64;
        p0 = p1;
        p1 = p2;
    }
    if n == 0 {
        return (1.0, 0.0);
    }
    let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

/// The 16-point rule, computed once.
pub fn gl16() -> &'static Rule {
    static RULE: OnceLock<Rule> = OnceLock::new();
    RULE.get_or_init(|| Rule::gauss_legendre(16))
}

/// The 8-point rule, computed once.
pub fn gl8() -> &'static Rule {
    static RULE: OnceLock<Rule> = OnceLock::new();
    RULE.get_or_init(|| Rule::gauss_legendre(8))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_of_degree_2n_minus_1_exactly() {
        for n in [1, 2, 3, 5, 8, 16, 33, 100] {
            let rule = Rule::gauss_legendre(n);
            for degree in 0..(2 * n).min(60) {
                let got: f64 = rule.nodes.iter().zip(&rule.weights).map(|(x, w)| w * x.powi(degree as i32)).sum();
                let exact = 1.0 / (degree as f64 + 1.0);
                assert!((got - exact).abs() < 1e-13, "n={n} degree={degree}: {got} vs {exact}");
            }
        }
    }

    #[test]
    fn gauss_legendre_matches_published_nodes() {
        // A&S Table 25.4, n = 3: ±√(3/5), 0 with weights 5/9, 8/9 on [−1, 1].
        let r = Rule::gauss_legendre(3);
        let x = (0.6f64).sqrt();
        assert!((r.nodes[0] - 0.5 * (1.0 - x)).abs() < 1e-15);
        assert!((r.nodes[1] - 0.5).abs() < 1e-15);
        assert!((r.weights[0] - 5.0 / 18.0).abs() < 1e-15);
        assert!((r.weights[1] - 8.0 / 18.0).abs() < 1e-15);
        // Large n stays accurate: the weights sum to 1 and nodes are sorted.
        let r = Rule::gauss_legendre(4096);
        let sum: f64 = r.weights.iter().sum();
        assert!((sum - 1.0).abs() < 1e-12, "{sum}");
        assert!(r.nodes.windows(2).all(|w| w[0] < w[1]));
    }
}

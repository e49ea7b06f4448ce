//! The speed ratio at equal error: for a row of error e reached in time t,
//! t_ref(e)/t, where t_ref(e) is the time the reference path tracer needs
//! to reach e. Above 1 the method is that many times faster than path
//! tracing to the same error; below 1, slower.
//!
//! t_ref comes from the reference's own rungs (time, error): made monotone
//! (the best error reached by each time), then interpolated linearly in
//! log–log between the two rungs around e. Beyond its first or last rung it
//! is extrapolated as Monte Carlo error falls, e ∝ t^(−1/2), and the ratio
//! is marked as extrapolated.

/// The reference's time to reach `error`, and whether it was extrapolated;
/// None without rungs or for an error of 0 (never reached).
pub fn time_to_reach(rungs: &[(f64, f64)], error: f64) -> Option<(f64, bool)> {
    if !(error.is_finite() && error > 0.0) {
        return None;
    }
    // The lower envelope over time: each rung that improved on all before.
    let mut envelope: Vec<(f64, f64)> = Vec::new();
    for &(t, e) in rungs {
        let usable = t.is_finite() && t > 0.0 && e.is_finite() && e > 0.0;
        if usable && envelope.last().is_none_or(|&(_, best)| e < best) {
            envelope.push((t, e));
        }
    }
    let (&(t0, e0), &(tn, en)) = (envelope.first()?, envelope.last()?);
    // e ∝ t^(−1/2), so t ∝ e^(−2).
    let monte_carlo = |t: f64, e: f64| t * (e / error).powi(2);
    if error >= e0 {
        return Some((monte_carlo(t0, e0), error > e0));
    }
    if error < en {
        return Some((monte_carlo(tn, en), true));
    }
    let i = envelope.windows(2).position(|w| w[1].1 <= error)?;
    let ((ta, ea), (tb, eb)) = (envelope[i], envelope[i + 1]);
    let f = (error.ln() - ea.ln()) / (eb.ln() - ea.ln());
    Some(((ta.ln() + f * (tb.ln() - ta.ln())).exp(), false))
}

/// t_ref(error)/seconds, with whether it was extrapolated.
pub fn speed_ratio(reference: &[(f64, f64)], seconds: f64, error: f64) -> Option<(f64, bool)> {
    let (t, extrapolated) = time_to_reach(reference, error)?;
    (seconds > 0.0).then_some((t / seconds, extrapolated))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a / b - 1.0).abs() < 1e-9
    }

    #[test]
    fn a_monte_carlo_curve_gives_its_own_times_back() {
        // e = 0.1/√t, sampled at t = 1, 4, 16.
        let reference = [(1.0, 0.1), (4.0, 0.05), (16.0, 0.025)];
        let (t, x) = time_to_reach(&reference, 0.05).unwrap();
        assert!(close(t, 4.0) && !x);
        // Between rungs, log–log interpolation is exact on a power law.
        let (t, x) = time_to_reach(&reference, 0.1 / 8f64.sqrt()).unwrap();
        assert!(close(t, 8.0) && !x);
        // Beyond either end: the same law, marked.
        let (t, x) = time_to_reach(&reference, 0.0125).unwrap();
        assert!(close(t, 64.0) && x);
        let (t, x) = time_to_reach(&reference, 0.2).unwrap();
        assert!(close(t, 0.25) && x);
        // A method at error 0.05 in 0.5 s is 8 times faster.
        let (r, _) = speed_ratio(&reference, 0.5, 0.05).unwrap();
        assert!(close(r, 8.0));
    }

    #[test]
    fn a_rung_worse_than_an_earlier_one_is_passed_over() {
        // The 4 s rung was unlucky (a firefly): the curve is the best so far.
        let reference = [(1.0, 0.1), (4.0, 0.12), (16.0, 0.025)];
        let (t, _) = time_to_reach(&reference, 0.05).unwrap();
        assert!(close(t, 4.0), "{t}");
    }

    #[test]
    fn nothing_to_measure_against_gives_none() {
        assert_eq!(time_to_reach(&[], 0.1), None);
        assert_eq!(time_to_reach(&[(1.0, 0.1)], 0.0), None);
        assert_eq!(time_to_reach(&[(0.0, 0.1), (1.0, f64::NAN)], 0.1), None);
        assert_eq!(speed_ratio(&[(1.0, 0.1)], 0.0, 0.1), None);
    }
}

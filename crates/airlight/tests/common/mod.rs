//! Helpers shared by the analytic integrator's tests: an adaptive
//! Gauss–Kronrod integrator in f64, the oracle the closed forms are checked
//! against.

/// Kronrod 15-point nodes on [−1, 1] (the non-negative half) and weights,
/// with the weights of the embedded 7-point Gauss rule (at the odd nodes),
/// as QUADPACK's qk15 tabulates them.
const XK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
const WK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
const WG: [f64; 4] =
    [0.129_484_966_168_869_7, 0.279_705_391_489_276_7, 0.381_830_050_505_118_9, 0.417_959_183_673_469_4];

/// The Kronrod estimate on [a, b] and its difference from the Gauss one.
fn gk15(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    let fc = f(c);
    let (mut k, mut g) = (WK[7] * fc, WG[3] * fc);
    for i in 0..7 {
        let pair = f(c - h * XK[i]) + f(c + h * XK[i]);
        k += WK[i] * pair;
        if i % 2 == 1 {
            g += WG[i / 2] * pair;
        }
    }
    (k * h, (k - g).abs() * h)
}

fn adapt(f: &dyn Fn(f64) -> f64, a: f64, b: f64, tol: f64, depth: u32) -> f64 {
    let (k, err) = gk15(f, a, b);
    if err <= tol || depth == 0 {
        return k;
    }
    let m = 0.5 * (a + b);
    adapt(f, a, m, 0.5 * tol, depth - 1) + adapt(f, m, b, 0.5 * tol, depth - 1)
}

/// ∫_a^b f by adaptive Gauss–Kronrod (7–15) bisection, to about `rel` of the
/// integral, with `cuts` (points where f peaks) as panel ends.
pub fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64, cuts: &[f64], rel: f64) -> f64 {
    let mut points = vec![a];
    points.extend(cuts.iter().copied().filter(|&c| c > a && c < b));
    points.push(b);
    let sum = |tol: f64| -> f64 { points.windows(2).map(|w| adapt(f, w[0], w[1], tol + f64::MIN_POSITIVE, 40)).sum() };
    let rough = sum(1e-3 * points.windows(2).map(|w| gk15(f, w[0], w[1]).0.abs()).sum::<f64>());
    sum(rel * rough.abs())
}

//! Combinations of distance fields. Union, intersection and subtraction of
//! exact distances give bounds (never more than the true distance), which is
//! all sphere tracing needs (Hart 1996, section 3). The smooth union is
//! Quilez's quadratic polynomial smooth minimum
//! (iquilezles.org/articles/smin): with h = max(k − |a − b|, 0)/k,
//! smin(a, b) = min(a, b) − h²k/4. Its partial derivatives are non-negative
//! and sum to 1, so it stays 1-Lipschitz, and it lies at most k/4 below min.

/// Union: min(a, b).
#[inline]
pub fn union(a: f32, b: f32) -> f32 {
    a.min(b)
}

/// Intersection: max(a, b).
#[inline]
pub fn intersection(a: f32, b: f32) -> f32 {
    a.max(b)
}

/// a with b cut away: max(a, −b).
#[inline]
pub fn subtraction(a: f32, b: f32) -> f32 {
    a.max(-b)
}

/// Smooth union with blend radius k > 0 (see the module notes).
#[inline]
pub fn smooth_union(a: f32, b: f32, k: f32) -> f32 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

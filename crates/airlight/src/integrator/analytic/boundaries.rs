//! Where a ray's light changes abruptly: the ray parameters at which it
//! crosses a spot light's cone, and the boundaries of the shadow volumes that
//! spheres, boxes, quads, triangles and planes cast from a point light.
//!
//! Every function adds candidate parameters t in the open interval (t₀, t₁)
//! to `out`; the caller sorts them and classifies each piece between two
//! consecutive candidates by one test at its middle. A candidate that is not
//! a real boundary only splits a piece in two, so the functions may be
//! generous; they must never miss a boundary.
//!
//! Rays are o + t·d with d of any length (instanced shapes are handled in
//! their own space, where an affine map keeps t), and all arithmetic is f64.

use glam::DVec3;

#[inline]
fn push(out: &mut Vec<f64>, t: f64, t0: f64, t1: f64) {
    if t > t0 && t < t1 {
        out.push(t);
    }
}

/// The real roots of a t² + 2 b t + c = 0, computed without cancellation
/// (the root of larger magnitude first, the other as c / (a · it)). A
/// vanishing `a` leaves the linear equation.
pub fn quadratic_roots(a: f64, b: f64, c: f64) -> [Option<f64>; 2] {
    let scale = a.abs().max(b.abs()).max(c.abs());
    if scale == 0.0 || !scale.is_finite() {
        return [None, None];
    }
    if a.abs() <= 1e-14 * scale {
        return if b != 0.0 { [Some(-c / (2.0 * b)), None] } else { [None, None] };
    }
    let disc = b * b - a * c;
    if disc < 0.0 {
        return [None, None];
    }
    let q = -(b + disc.sqrt().copysign(b));
    if q == 0.0 {
        return [Some(0.0), None];
    }
    [Some(q / a), Some(c / q)]
}

/// Crossings of the ray with the double cone {x : ((x − apex)·axis)² = cos²α |x − apex|²}
/// (axis unit): both nappes, so also the cone of a spot whose half angle α
/// exceeds 90°. With w = o − apex + t d, the condition is the quadratic
/// (w·A)² − cos²α |w|² = 0.
pub fn cone_crossings(
    apex: DVec3,
    axis: DVec3,
    cos_half: f64,
    o: DVec3,
    d: DVec3,
    (t0, t1): (f64, f64),
    out: &mut Vec<f64>,
) {
    let w0 = o - apex;
    let (alpha, beta) = (w0.dot(axis), d.dot(axis));
    let c2 = cos_half * cos_half;
    let a = beta * beta - c2 * d.length_squared();
    let b = alpha * beta - c2 * w0.dot(d);
    let c = alpha * alpha - c2 * w0.length_squared();
    for t in quadratic_roots(a, b, c).into_iter().flatten() {
        push(out, t, t0, t1);
    }
}

/// Shadow boundaries of a ball (center, radius) lit from `light`: where the
/// ray enters or leaves the ball, and where the segment from the light to
/// the ray's point grazes the sphere. With c = center − light and
/// w(t) = o − light + t d, grazing means the distance from the centre to the
/// line of w is the radius: (c·w)² = (|c|² − R²)|w|², a quadratic in t, of
/// which only roots with c·w > 0 (the sphere lies toward the point, not
/// behind the light) count. A light inside the ball has no grazing lines.
pub fn sphere_boundaries(
    light: DVec3,
    center: DVec3,
    radius: f64,
    o: DVec3,
    d: DVec3,
    (t0, t1): (f64, f64),
    out: &mut Vec<f64>,
) {
    let r2 = radius * radius;
    // The ray through the ball: |o − center + t d|² = R².
    let oc = o - center;
    for t in quadratic_roots(d.length_squared(), oc.dot(d), oc.length_squared() - r2).into_iter().flatten() {
        push(out, t, t0, t1);
    }
    let c = center - light;
    let k = c.length_squared() - r2;
    if k <= 0.0 {
        return;
    }
    let w0 = o - light;
    let (alpha, beta) = (c.dot(w0), c.dot(d));
    let a = beta * beta - k * d.length_squared();
    let b = alpha * beta - k * w0.dot(d);
    let cc = alpha * alpha - k * w0.length_squared();
    for t in quadratic_roots(a, b, cc).into_iter().flatten() {
        if alpha + beta * t > 0.0 {
            push(out, t, t0, t1);
        }
    }
}

/// Shadow boundaries of a convex polygon or polyhedron given by its edges,
/// lit from `light`. In the plane Π through the light and the ray's line,
/// the shape's cross-section is a convex polygon whose vertices are where
/// Π cuts the shape's edges; the segment from the light to the ray's point
/// starts or stops touching the section only when it passes through such a
/// vertex q. Each q gives the t where the line light→q meets the ray's line,
/// kept when q lies between the light and that point. The crossings of the
/// ray with the shape's surface, the other boundaries, come from the caller.
/// When the ray's line passes through the light (Π undefined) the only
/// extra boundary is the light's own parameter.
pub fn edge_boundaries(
    light: DVec3,
    edges: &[(DVec3, DVec3)],
    o: DVec3,
    d: DVec3,
    (t0, t1): (f64, f64),
    out: &mut Vec<f64>,
) {
    let w0 = o - light;
    let n = d.cross(w0);
    let scale = d.length() * w0.length();
    if n.length() <= 1e-12 * scale {
        push(out, -w0.dot(d) / d.length_squared(), t0, t1);
        return;
    }
    for &(a, b) in edges {
        let (sa, sb) = (n.dot(a - light), n.dot(b - light));
        if (sa > 0.0 && sb > 0.0) || (sa < 0.0 && sb < 0.0) || sa == sb {
            continue;
        }
        let q = a + (b - a) * (sa / (sa - sb));
        let v = q - light;
        // w0 + t d = λ v: cross with v, then dot with d × v.
        let dv = d.cross(v);
        let dv2 = dv.length_squared();
        if dv2 <= 1e-24 * d.length_squared() * v.length_squared() {
            continue;
        }
        let t = -w0.cross(v).dot(dv) / dv2;
        let lambda = (w0 + d * t).dot(v) / v.length_squared();
        if lambda > 1.0 - 1e-9 {
            push(out, t, t0, t1);
        }
    }
}

/// The twelve edges of the box [min, max].
pub fn box_edges(min: DVec3, max: DVec3) -> [(DVec3, DVec3); 12] {
    let corner = |i: usize| {
        DVec3::new(
            if i & 1 == 0 { min.x } else { max.x },
            if i & 2 == 0 { min.y } else { max.y },
            if i & 4 == 0 { min.z } else { max.z },
        )
    };
    let mut edges = [(DVec3::ZERO, DVec3::ZERO); 12];
    let mut k = 0;
    for i in 0..8 {
        for bit in [1, 2, 4] {
            if i & bit == 0 {
                edges[k] = (corner(i), corner(i | bit));
                k += 1;
            }
        }
    }
    edges
}

/// Shadow boundaries of the box [min, max]: its edges' ([`edge_boundaries`])
/// and the ray's entry and exit (slabs, Kay and Kajiya 1986).
pub fn box_boundaries(light: DVec3, min: DVec3, max: DVec3, o: DVec3, d: DVec3, range: (f64, f64), out: &mut Vec<f64>) {
    edge_boundaries(light, &box_edges(min, max), o, d, range, out);
    let inv = d.recip();
    let (ta, tb) = ((min - o) * inv, (max - o) * inv);
    let near = ta.min(tb).max_element();
    let far = ta.max(tb).min_element();
    if near <= far {
        push(out, near, range.0, range.1);
        push(out, far, range.0, range.1);
    }
}

/// Shadow boundaries of a parallelogram or triangle (`vertices` in order):
/// its edges' and the ray's crossing of its plane (kept whether or not it
/// falls inside the polygon; a spare candidate does no harm).
pub fn polygon_boundaries(light: DVec3, vertices: &[DVec3], o: DVec3, d: DVec3, range: (f64, f64), out: &mut Vec<f64>) {
    let mut edges = [(DVec3::ZERO, DVec3::ZERO); 4];
    let n = vertices.len().min(4);
    for i in 0..n {
        edges[i] = (vertices[i], vertices[(i + 1) % n]);
    }
    edge_boundaries(light, &edges[..n], o, d, range, out);
    let normal = (vertices[1] - vertices[0]).cross(vertices[n - 1] - vertices[0]);
    plane_boundaries(vertices[0], normal, o, d, range, out);
}

/// The one shadow boundary of an infinite plane: where the ray crosses it.
pub fn plane_boundaries(point: DVec3, normal: DVec3, o: DVec3, d: DVec3, (t0, t1): (f64, f64), out: &mut Vec<f64>) {
    let denom = normal.dot(d);
    if denom != 0.0 {
        push(out, normal.dot(point - o) / denom, t0, t1);
    }
}

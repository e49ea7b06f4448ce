//! Signed distance fields: a tree of exact primitives, transforms and
//! combinations, traced by sphere tracing (trace.rs). An SDF object sits in
//! the scene's BVH by its bounding box and is sphere traced inside it, so SDF
//! and analytic shapes mix in one scene; an SDF without a bound (one holding a
//! plane that nothing bounds) is traced like an infinite plane, on its own.

mod ops;
pub mod primitives;
mod trace;

pub use ops::{intersection, smooth_union, subtraction, union};
pub use trace::{MAX_STEPS, hit_epsilon, sdf_normal, sphere_trace};

use glam::{Affine3A, Mat3, Vec3};

/// A signed distance field. Every variant's `distance` is exact or a lower
/// bound of the true distance (1-Lipschitz), so sphere tracing never steps
/// through a surface.
#[derive(Clone, Debug, PartialEq)]
pub enum Sdf {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// Axis-aligned box from min to max.
    Box {
        min: Vec3,
        max: Vec3,
    },
    /// A box from min to max with edges rounded by `rounding`.
    RoundBox {
        min: Vec3,
        max: Vec3,
        rounding: f32,
    },
    /// Torus about the y axis through `center`.
    Torus {
        center: Vec3,
        major_radius: f32,
        minor_radius: f32,
    },
    /// All points within `radius` of the segment [a, b].
    Capsule {
        a: Vec3,
        b: Vec3,
        radius: f32,
    },
    /// A capped cylinder whose axis runs from a to b.
    Cylinder {
        a: Vec3,
        b: Vec3,
        radius: f32,
    },
    /// The half-space below a plane (`normal` is unit and points out).
    Plane {
        point: Vec3,
        normal: Vec3,
    },
    /// `inner` placed by `world_from_local`. The distance is the inner one
    /// times the smallest singular value of the linear part (`lipschitz`),
    /// which is exact for rotations with uniform scale and a lower bound
    /// under non-uniform scale: |p − q| ≥ σ_min·|M⁻¹(p − q)|.
    Transformed {
        inner: std::boxed::Box<Sdf>,
        local_from_world: Affine3A,
        lipschitz: f32,
    },
    Union(Vec<Sdf>),
    Intersection(Vec<Sdf>),
    /// The first child with all later ones cut away.
    Subtraction(Vec<Sdf>),
    /// Children blended pairwise in order by the smooth minimum of radius `blend`.
    SmoothUnion {
        children: Vec<Sdf>,
        blend: f32,
    },
}

impl Sdf {
    /// The field under `world_from_local`: a `Transformed` node, or nothing
    /// for the identity.
    pub fn transformed(self, world_from_local: Affine3A) -> Sdf {
        if world_from_local == Affine3A::IDENTITY {
            return self;
        }
        let linear = Mat3::from(world_from_local.matrix3);
        let lipschitz = smallest_singular_value(linear);
        match self {
            // Fold nested transforms into one.
            Sdf::Transformed { inner, local_from_world, .. } => {
                let world_from_inner = world_from_local * local_from_world.inverse();
                let lipschitz = smallest_singular_value(Mat3::from(world_from_inner.matrix3));
                Sdf::Transformed { inner, local_from_world: world_from_inner.inverse(), lipschitz }
            }
            other => Sdf::Transformed {
                inner: std::boxed::Box::new(other),
                local_from_world: world_from_local.inverse(),
                lipschitz,
            },
        }
    }

    /// The signed distance (or a lower bound of it) from `p` to the surface.
    pub fn distance(&self, p: Vec3) -> f32 {
        match self {
            Sdf::Sphere { center, radius } => primitives::sphere(p, *center, *radius),
            Sdf::Box { min, max } => primitives::cuboid(p, 0.5 * (*min + *max), 0.5 * (*max - *min)),
            Sdf::RoundBox { min, max, rounding } => {
                primitives::round_box(p, 0.5 * (*min + *max), 0.5 * (*max - *min), *rounding)
            }
            Sdf::Torus { center, major_radius, minor_radius } => {
                primitives::torus(p, *center, *major_radius, *minor_radius)
            }
            Sdf::Capsule { a, b, radius } => primitives::capsule(p, *a, *b, *radius),
            Sdf::Cylinder { a, b, radius } => primitives::cylinder(p, *a, *b, *radius),
            Sdf::Plane { point, normal } => primitives::plane(p, *point, *normal),
            Sdf::Transformed { inner, local_from_world, lipschitz } => {
                inner.distance(local_from_world.transform_point3(p)) * lipschitz
            }
            Sdf::Union(children) => fold(children, p, union),
            Sdf::Intersection(children) => fold(children, p, intersection),
            Sdf::Subtraction(children) => {
                let (first, rest) = children.split_first().expect("a subtraction has children");
                rest.iter().fold(first.distance(p), |d, c| subtraction(d, c.distance(p)))
            }
            Sdf::SmoothUnion { children, blend } => fold(children, p, |a, b| smooth_union(a, b, *blend)),
        }
    }

    /// An axis-aligned box holding the surface, or None when nothing bounds it
    /// (a plane, or a union with one).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        match self {
            Sdf::Sphere { center, radius } => Some((*center - *radius, *center + *radius)),
            Sdf::Box { min, max } | Sdf::RoundBox { min, max, .. } => Some((*min, *max)),
            Sdf::Torus { center, major_radius, minor_radius } => {
                let e = Vec3::new(major_radius + minor_radius, *minor_radius, major_radius + minor_radius);
                Some((*center - e, *center + e))
            }
            Sdf::Capsule { a, b, radius } | Sdf::Cylinder { a, b, radius } => {
                Some((a.min(*b) - *radius, a.max(*b) + *radius))
            }
            Sdf::Plane { .. } => None,
            Sdf::Transformed { inner, local_from_world, .. } => {
                let (lo, hi) = inner.bounds()?;
                let world_from_local = local_from_world.inverse();
                let mut min = Vec3::INFINITY;
                let mut max = Vec3::NEG_INFINITY;
                for i in 0..8 {
                    let corner = Vec3::new(
                        if i & 1 == 0 { lo.x } else { hi.x },
                        if i & 2 == 0 { lo.y } else { hi.y },
                        if i & 4 == 0 { lo.z } else { hi.z },
                    );
                    let c = world_from_local.transform_point3(corner);
                    min = min.min(c);
                    max = max.max(c);
                }
                Some((min, max))
            }
            Sdf::Union(children) => union_bounds(children, 0.0),
            Sdf::SmoothUnion { children, blend } => union_bounds(children, 0.25 * blend),
            Sdf::Intersection(children) => {
                children.iter().filter_map(Sdf::bounds).reduce(|a, b| (a.0.max(b.0), a.1.min(b.1)))
            }
            Sdf::Subtraction(children) => children.first()?.bounds(),
        }
    }

    /// The unit outward normal at `p`: the field's gradient (trace.rs).
    pub fn normal(&self, p: Vec3) -> Vec3 {
        sdf_normal(self, p)
    }

    /// Checks the parameters: positive radii, min < max, rounding no more
    /// than half the smallest side, non-empty combinations, finite values.
    pub fn validate(&self) -> Result<(), String> {
        let positive = |v: f32, what: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("{what} must be a positive finite number, got {v}"))
            }
        };
        let finite =
            |v: Vec3, what: &str| if v.is_finite() { Ok(()) } else { Err(format!("{what} must be finite, got {v}")) };
        match self {
            Sdf::Sphere { center, radius } => {
                finite(*center, "center")?;
                positive(*radius, "radius")
            }
            Sdf::Box { min, max } | Sdf::RoundBox { min, max, .. } => {
                finite(*min, "min")?;
                finite(*max, "max")?;
                if !min.cmplt(*max).all() {
                    return Err(format!("min must be less than max on every axis, got min {min} max {max}"));
                }
                if let Sdf::RoundBox { rounding, .. } = self {
                    let half = 0.5 * (*max - *min).min_element();
                    if !(rounding.is_finite() && *rounding >= 0.0 && *rounding <= half) {
                        return Err(format!(
                            "rounding must lie in [0, {half}] (half the smallest side), got {rounding}"
                        ));
                    }
                }
                Ok(())
            }
            Sdf::Torus { center, major_radius, minor_radius } => {
                finite(*center, "center")?;
                positive(*major_radius, "major_radius")?;
                positive(*minor_radius, "minor_radius")
            }
            Sdf::Capsule { a, b, radius } | Sdf::Cylinder { a, b, radius } => {
                finite(*a, "a")?;
                finite(*b, "b")?;
                if matches!(self, Sdf::Cylinder { .. }) && a == b {
                    return Err("a cylinder's a and b must differ".into());
                }
                positive(*radius, "radius")
            }
            Sdf::Plane { point, normal } => {
                finite(*point, "point")?;
                finite(*normal, "normal")?;
                if (normal.length() - 1.0).abs() > 1e-4 {
                    return Err(format!("normal must be a unit vector, got {normal}"));
                }
                Ok(())
            }
            Sdf::Transformed { inner, local_from_world, lipschitz } => {
                if !(local_from_world.is_finite() && lipschitz.is_finite() && *lipschitz > 0.0) {
                    return Err("the transform must be finite and invertible".into());
                }
                inner.validate()
            }
            Sdf::Union(c) | Sdf::Intersection(c) | Sdf::Subtraction(c) | Sdf::SmoothUnion { children: c, .. } => {
                if c.is_empty() {
                    return Err("a combination needs at least one child".into());
                }
                if let Sdf::SmoothUnion { blend, .. } = self {
                    positive(*blend, "blend")?;
                }
                c.iter().try_for_each(Sdf::validate)
            }
        }
    }
}

fn fold(children: &[Sdf], p: Vec3, op: impl Fn(f32, f32) -> f32) -> f32 {
    let mut iter = children.iter();
    let first = iter.next().map_or(f32::INFINITY, |c| c.distance(p));
    iter.fold(first, |d, c| op(d, c.distance(p)))
}

fn union_bounds(children: &[Sdf], pad: f32) -> Option<(Vec3, Vec3)> {
    let mut acc: Option<(Vec3, Vec3)> = None;
    for c in children {
        let (lo, hi) = c.bounds()?;
        acc = Some(match acc {
            Some((a, b)) => (a.min(lo), b.max(hi)),
            None => (lo, hi),
        });
    }
    acc.map(|(lo, hi)| (lo - pad, hi + pad))
}

/// The smallest singular value of a 3×3 matrix: the square root of the
/// smallest eigenvalue of MᵀM, found by the closed form for symmetric 3×3
/// eigenvalues (Smith, "Eigenvalues of a symmetric 3×3 matrix", CACM 1961).
fn smallest_singular_value(m: Mat3) -> f32 {
    let a = (m.transpose() * m).to_cols_array_2d().map(|c| c.map(f64::from));
    let p1 = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
    let q = (a[0][0] + a[1][1] + a[2][2]) / 3.0;
    if p1 <= 1e-18 * q * q {
        return a[0][0].min(a[1][1]).min(a[2][2]).max(0.0).sqrt() as f32;
    }
    let p2 = (a[0][0] - q).powi(2) + (a[1][1] - q).powi(2) + (a[2][2] - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    let mut b = a;
    for (i, row) in b.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (a[i][j] - if i == j { q } else { 0.0 }) / p;
        }
    }
    let det = b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) - b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0])
        + b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0]);
    let phi = (0.5 * det).clamp(-1.0, 1.0).acos() / 3.0;
    // The smallest of the three eigenvalues q + 2p cos(φ + 2πk/3).
    let smallest = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
    smallest.max(0.0).sqrt() as f32
}

#[cfg(test)]
mod tests;

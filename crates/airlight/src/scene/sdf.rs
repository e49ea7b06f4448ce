//! Signed distance field objects in the scene file (`type = "sdf"`): a tree
//! of nodes, each a primitive or a combination of `children`, each placed by
//! its own translate/rotate/scale. The object table is the root node.
//!
//! ```toml
//! [[objects]]
//! type = "sdf"
//! material = "stone"
//! shape = "smooth_union"          # sphere | box | round_box | torus | capsule | cylinder | plane
//! blend = 0.3                     #   | union | intersection | subtraction | smooth_union
//! children = [
//!   { shape = "box", min = [-1, 0, -1], max = [1, 1, 1] },
//!   { shape = "sphere", radius = 0.6, translate = [0, 1.2, 0] },
//! ]
//! ```

use super::build::{Checker, Result};
use super::desc::{ObjectDesc, SdfNodeDesc, SdfShape};
use crate::geometry::Sdf;
use glam::Vec3;
use std::ops::Range;
use toml::Spanned;

impl Checker<'_> {
    /// The field of an `sdf` object (its own transform is applied by the caller).
    pub(super) fn sdf_object(&self, span: Range<usize>, label: &str, o: &ObjectDesc) -> Result<Sdf> {
        let Some(shape) = o.shape else {
            return Err(self.err(
                span,
                format!(
                    "{label}: an sdf needs `shape`: sphere, box, round_box, torus, capsule, cylinder, plane, \
                     union, intersection, subtraction or smooth_union"
                ),
            ));
        };
        let root = SdfNodeDesc {
            shape,
            center: o.center,
            radius: o.radius,
            min: o.min,
            max: o.max,
            point: o.point,
            normal: o.normal,
            a: o.a,
            b: o.b,
            major_radius: o.major_radius,
            minor_radius: o.minor_radius,
            rounding: o.rounding,
            blend: o.blend,
            children: o.children.clone(),
            translate: None,
            rotate: None,
            scale: None,
        };
        self.sdf_node(span, label, &root, 0)
    }

    fn sdf_node(&self, span: Range<usize>, label: &str, n: &SdfNodeDesc, depth: usize) -> Result<Sdf> {
        if depth > 64 {
            return Err(self.err(span, format!("{label}: SDF trees may nest at most 64 deep")));
        }
        let kind = shape_name(n.shape);
        let fields: [(&str, bool); 13] = [
            ("center", n.center.is_some()),
            ("radius", n.radius.is_some()),
            ("min", n.min.is_some()),
            ("max", n.max.is_some()),
            ("point", n.point.is_some()),
            ("normal", n.normal.is_some()),
            ("a", n.a.is_some()),
            ("b", n.b.is_some()),
            ("major_radius", n.major_radius.is_some()),
            ("minor_radius", n.minor_radius.is_some()),
            ("rounding", n.rounding.is_some()),
            ("blend", n.blend.is_some()),
            ("children", n.children.is_some()),
        ];
        let (required, optional): (&[&str], &[&str]) = match n.shape {
            SdfShape::Sphere => (&["radius"], &["center"]),
            SdfShape::Box => (&["min", "max"], &[]),
            SdfShape::RoundBox => (&["min", "max", "rounding"], &[]),
            SdfShape::Torus => (&["major_radius", "minor_radius"], &["center"]),
            SdfShape::Capsule | SdfShape::Cylinder => (&["a", "b", "radius"], &[]),
            SdfShape::Plane => (&["normal"], &["point"]),
            SdfShape::Union | SdfShape::Intersection | SdfShape::Subtraction => (&["children"], &[]),
            SdfShape::SmoothUnion => (&["children", "blend"], &[]),
        };
        let label = format!("{label} ({kind})");
        self.check_fields(span.clone(), &label, kind, &fields, required, optional)?;
        let point = |p: Option<super::desc::Point>, name: &str, default: Vec3| {
            self.finite3(span.clone(), &format!("{label}.{name}"), p.map_or(default, |p| p.0))
        };
        let number = |v: Option<f32>| v.unwrap_or(0.0);
        let sdf = match n.shape {
            SdfShape::Sphere => {
                Sdf::Sphere { center: point(n.center, "center", Vec3::ZERO)?, radius: number(n.radius) }
            }
            SdfShape::Box => Sdf::Box { min: point(n.min, "min", Vec3::ZERO)?, max: point(n.max, "max", Vec3::ZERO)? },
            SdfShape::RoundBox => Sdf::RoundBox {
                min: point(n.min, "min", Vec3::ZERO)?,
                max: point(n.max, "max", Vec3::ZERO)?,
                rounding: number(n.rounding),
            },
            SdfShape::Torus => Sdf::Torus {
                center: point(n.center, "center", Vec3::ZERO)?,
                major_radius: number(n.major_radius),
                minor_radius: number(n.minor_radius),
            },
            SdfShape::Capsule | SdfShape::Cylinder => {
                let (a, b) = (point(n.a, "a", Vec3::ZERO)?, point(n.b, "b", Vec3::ZERO)?);
                let radius = number(n.radius);
                if n.shape == SdfShape::Capsule {
                    Sdf::Capsule { a, b, radius }
                } else {
                    Sdf::Cylinder { a, b, radius }
                }
            }
            SdfShape::Plane => {
                let normal = self.direction(span.clone(), &format!("{label}.normal"), n.normal.unwrap().0)?;
                Sdf::Plane { point: point(n.point, "point", Vec3::ZERO)?, normal }
            }
            SdfShape::Union | SdfShape::Intersection | SdfShape::Subtraction | SdfShape::SmoothUnion => {
                let children = n.children.as_deref().unwrap_or_default();
                if children.is_empty() {
                    return Err(self.err_field(span, "children", format!("{label}: `children` must not be empty")));
                }
                let built = children
                    .iter()
                    .enumerate()
                    .map(|(i, c): (usize, &Spanned<SdfNodeDesc>)| {
                        self.sdf_node(c.span(), &format!("{label}.children[{i}]"), c.get_ref(), depth + 1)
                    })
                    .collect::<Result<Vec<Sdf>>>()?;
                match n.shape {
                    SdfShape::Union => Sdf::Union(built),
                    SdfShape::Intersection => Sdf::Intersection(built),
                    SdfShape::Subtraction => Sdf::Subtraction(built),
                    _ => Sdf::SmoothUnion { children: built, blend: number(n.blend) },
                }
            }
        };
        // Parameters of this node (children were checked on their own).
        let own = match &sdf {
            Sdf::Union(_) | Sdf::Intersection(_) | Sdf::Subtraction(_) => Ok(()),
            Sdf::SmoothUnion { blend, .. } => {
                if blend.is_finite() && *blend > 0.0 {
                    Ok(())
                } else {
                    Err(format!("blend must be a positive finite number, got {blend}"))
                }
            }
            leaf => leaf.validate(),
        };
        if let Err(why) = own {
            let field = why.split_whitespace().next().unwrap_or("");
            return Err(self.err_field(span, &format!("{label}.{field}"), format!("{label}: {why}")));
        }
        let transform = self.transform_parts(span, &label, n.translate, n.rotate, n.scale)?;
        Ok(sdf.transformed(transform))
    }
}

fn shape_name(shape: SdfShape) -> &'static str {
    match shape {
        SdfShape::Sphere => "sphere",
        SdfShape::Box => "box",
        SdfShape::RoundBox => "round_box",
        SdfShape::Torus => "torus",
        SdfShape::Capsule => "capsule",
        SdfShape::Cylinder => "cylinder",
        SdfShape::Plane => "plane",
        SdfShape::Union => "union",
        SdfShape::Intersection => "intersection",
        SdfShape::Subtraction => "subtraction",
        SdfShape::SmoothUnion => "smooth_union",
    }
}

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

use super::check::{Checker, Result};
use super::desc::{Point, SdfNodeDesc};
use super::tables::{TableAt, TableValue, element, field};
use crate::geometry::Sdf;
use glam::Vec3;
use toml::Spanned;

/// How deep SDF nodes may nest.
const MAX_DEPTH: usize = 64;

impl Checker<'_> {
    /// The field of an `sdf` object, whose table (less the object's own
    /// keys) is its root node; its transform is applied by the caller.
    pub(super) fn sdf_object(&self, label: &str, root: &TableValue<'_>) -> Result<Sdf> {
        self.sdf_node(label, root, 0)
    }

    fn sdf_node(&self, label: &str, value: &TableValue<'_>, depth: usize) -> Result<Sdf> {
        if depth > MAX_DEPTH {
            return Err(self.err(value.span(), format!("{label}: SDF trees may nest at most {MAX_DEPTH} deep")));
        }
        let read = self.read_table::<SdfNodeDesc>(value, label)?;
        let span = read.table.span();
        let label = format!("{label} ({})", read.name);
        let point = |p: Option<Point>, name: &str| {
            self.finite3(span.clone(), &format!("{label}.{name}"), p.map_or(Vec3::ZERO, |p| p.0))
        };
        let children = |given: &[Spanned<TableAt>]| self.sdf_children(&label, &read.table, given, depth);
        let sdf = match &read.kind {
            SdfNodeDesc::Sphere(n) => Sdf::Sphere { center: point(n.center, "center")?, radius: n.radius },
            SdfNodeDesc::Box(n) => Sdf::Box { min: point(Some(n.min), "min")?, max: point(Some(n.max), "max")? },
            SdfNodeDesc::RoundBox(n) => {
                Sdf::RoundBox { min: point(Some(n.min), "min")?, max: point(Some(n.max), "max")?, rounding: n.rounding }
            }
            SdfNodeDesc::Torus(n) => Sdf::Torus {
                center: point(n.center, "center")?,
                major_radius: n.major_radius,
                minor_radius: n.minor_radius,
            },
            SdfNodeDesc::Capsule(n) => {
                Sdf::Capsule { a: point(Some(n.a), "a")?, b: point(Some(n.b), "b")?, radius: n.radius }
            }
            SdfNodeDesc::Cylinder(n) => {
                Sdf::Cylinder { a: point(Some(n.a), "a")?, b: point(Some(n.b), "b")?, radius: n.radius }
            }
            SdfNodeDesc::Plane(n) => {
                let normal = self.direction(span.clone(), &format!("{label}.normal"), n.normal.0)?;
                Sdf::Plane { point: point(n.point, "point")?, normal }
            }
            SdfNodeDesc::Union(n) => Sdf::Union(children(&n.children)?),
            SdfNodeDesc::Intersection(n) => Sdf::Intersection(children(&n.children)?),
            SdfNodeDesc::Subtraction(n) => Sdf::Subtraction(children(&n.children)?),
            SdfNodeDesc::SmoothUnion(n) => Sdf::SmoothUnion { children: children(&n.children)?, blend: n.blend },
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
        let place = &read.shared;
        let transform = self.transform_parts(span, &label, place.translate, place.rotate, place.scale)?;
        Ok(sdf.transformed(transform))
    }

    /// A combination's `children` (`given`, in the node's `table`), each
    /// read as a node; at least one.
    fn sdf_children(
        &self,
        label: &str,
        table: &TableValue<'_>,
        given: &[Spanned<TableAt>],
        depth: usize,
    ) -> Result<Vec<Sdf>> {
        let list = field(table, "children");
        if given.is_empty() {
            let span = list.map_or(table.span(), |l| l.span());
            return Err(self.err(span, format!("{label}: `children` must not be empty")));
        }
        let mut children = Vec::with_capacity(given.len());
        for (i, child) in given.iter().enumerate() {
            let value = list.and_then(|l| element(l, i));
            let value =
                value.ok_or_else(|| self.err(child.span(), format!("{label}.children[{i}] is not in the file")))?;
            children.push(self.sdf_node(&format!("{label}.children[{i}]"), value, depth + 1)?);
        }
        Ok(children)
    }
}

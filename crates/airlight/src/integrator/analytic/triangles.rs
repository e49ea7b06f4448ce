//! Exact volumetric shadows of triangle meshes.
//!
//! A triangle lit from a point L outside its plane shadows the points x for
//! which the segment [x, L] crosses it: the part of the cone from L through
//! the triangle that lies beyond the triangle's plane. That set is the
//! intersection of four half-spaces (the three planes through L and an
//! edge, and the triangle's plane), so a ray's shadowed part is one
//! interval, found by clipping the ray against the four planes
//! ([`triangle_shadow`]) with no shadow ray. A mesh's shadow is the union
//! of its triangles' shadows, whatever the mesh's shape and whether the
//! light or the camera are inside it. Two triangles that share an edge
//! compute the plane through L and that edge from the same two vertices,
//! so their intervals meet exactly, with no crack of light between them.
//!
//! Only triangles that can meet a shadow segment matter: those that touch
//! the triangle (L, o + t₀ d, o + t₁ d) swept by the segments from L to the
//! ray. A bounding volume hierarchy over the triangles (median splits,
//! boxes in f64) is walked with a conservative box–triangle test
//! (separating axes: the triangle's normal, its three in-plane edge
//! normals and the coordinate axes).

use super::clearance::triangle_distance;
use crate::geometry::Shape;
use crate::scene::Scene;
use glam::DVec3;

/// One triangle of a mesh, its vertices as the mesh gives them.
#[derive(Clone, Copy, Debug)]
struct Triangle {
    vertices: [DVec3; 3],
}

/// A node of the hierarchy: a box and either two children (`count` = 0,
/// children at `first` and `first + 1`) or `count` triangles from `first`.
#[derive(Clone, Copy, Debug)]
struct Node {
    min: DVec3,
    max: DVec3,
    first: u32,
    count: u32,
}

/// Triangles per leaf.
const LEAF: usize = 4;
/// Depth bound of the traversal stack (median splits of up to 2³² triangles
/// need at most 32 levels; each level leaves one sibling on the stack).
const STACK: usize = 64;

/// The scene's mesh triangles, ready for shadow queries.
#[derive(Clone, Debug, Default)]
pub(super) struct MeshShadows {
    triangles: Vec<Triangle>,
    nodes: Vec<Node>,
}

impl MeshShadows {
    /// The hierarchy over `triangles` (each given by its three vertices).
    pub fn new(triangles: impl IntoIterator<Item = [DVec3; 3]>) -> MeshShadows {
        let mut triangles: Vec<Triangle> = triangles
            .into_iter()
            .filter(|v| v.iter().all(|p| p.is_finite()))
            .map(|vertices| Triangle { vertices })
            .collect();
        let mut nodes = Vec::new();
        if !triangles.is_empty() {
            nodes.push(Node { min: DVec3::ZERO, max: DVec3::ZERO, first: 0, count: 0 });
            build(&mut triangles, 0, 0, &mut nodes);
        }
        MeshShadows { triangles, nodes }
    }

    /// The triangles of the scene's meshes, with their vertices as the
    /// meshes give them: two triangles that share an edge share its
    /// vertices exactly, so their shadows meet with no crack (the BVH's
    /// triangles keep edge vectors instead, rounded in f32).
    pub fn of_scene(scene: &Scene) -> MeshShadows {
        let mut triangles = Vec::new();
        for (shape, _) in scene.objects() {
            let baked;
            let shape = match shape {
                Shape::Transformed { shape, world_from_local } => {
                    baked = shape.as_ref().clone().transformed(*world_from_local);
                    &baked
                }
                other => other,
            };
            if let Shape::Mesh { positions, triangles: indices, .. } = shape {
                for tri in indices {
                    triangles.push(tri.map(|i| positions.get(i as usize).map_or(DVec3::NAN, |p| p.as_dvec3())));
                }
            }
        }
        MeshShadows::new(triangles)
    }

    #[cfg(test)]
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Whether some triangle comes closer than `radius` to `p`.
    pub fn surface_within(&self, p: DVec3, radius: f64) -> bool {
        self.triangles.iter().any(|t| triangle_distance(p, t.vertices) < radius)
    }

    /// Appends to `out` the shadow interval, within `range`, of every
    /// triangle that shadows part of the ray o + t d from `light` (not
    /// merged: the caller takes the union).
    pub fn shadows(&self, light: DVec3, o: DVec3, d: DVec3, range: (f64, f64), out: &mut Vec<(f64, f64)>) {
        if self.nodes.is_empty() {
            return;
        }
        let swept = Swept::new(light, o + d * range.0, o + d * range.1);
        let mut stack = [0u32; STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            if !swept.may_touch(node.min, node.max) {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                for t in &self.triangles[first..first + node.count as usize] {
                    if let Some(interval) = triangle_shadow(light, t.vertices, o, d, range) {
                        out.push(interval);
                    }
                }
            } else if top + 2 <= STACK {
                stack[top] = node.first;
                stack[top + 1] = node.first + 1;
                top += 2;
            }
        }
    }
}

/// Builds the subtree of `nodes[index]` over `triangles[offset..]` (the
/// slice given), splitting at the median of the centroids along the box's
/// longest axis.
fn build(triangles: &mut [Triangle], offset: usize, index: usize, nodes: &mut Vec<Node>) {
    let (mut min, mut max) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for t in triangles.iter() {
        for v in t.vertices {
            min = min.min(v);
            max = max.max(v);
        }
    }
    if triangles.len() <= LEAF {
        nodes[index] = Node { min, max, first: offset as u32, count: triangles.len() as u32 };
        return;
    }
    let extent = max - min;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let centroid = |t: &Triangle| (t.vertices[0] + t.vertices[1] + t.vertices[2])[axis];
    let half = triangles.len() / 2;
    triangles.select_nth_unstable_by(half, |a, b| centroid(a).total_cmp(&centroid(b)));
    let first = nodes.len();
    nodes[index] = Node { min, max, first: first as u32, count: 0 };
    nodes.push(Node { min, max, first: 0, count: 0 });
    nodes.push(Node { min, max, first: 0, count: 0 });
    let (left, right) = triangles.split_at_mut(half);
    build(left, offset, first, nodes);
    build(right, offset + half, first + 1, nodes);
}

/// The triangle swept by the segments from a light to the points of a ray
/// segment [a, b], with the separating axes of its box test.
struct Swept {
    corners: [DVec3; 3],
    min: DVec3,
    max: DVec3,
    /// The plane's normal (zero when the triangle is degenerate: the ray's
    /// line passes through the light; then only the box overlap is tested).
    normal: DVec3,
    /// Outward in-plane normal of each edge.
    edges: [DVec3; 3],
}

impl Swept {
    fn new(light: DVec3, a: DVec3, b: DVec3) -> Swept {
        let corners = [light, a, b];
        let mut normal = (a - light).cross(b - light);
        let scale = (a - light).length() * (b - light).length();
        if normal.length() <= 1e-12 * scale || !normal.is_finite() {
            normal = DVec3::ZERO;
        }
        let mut edges = [DVec3::ZERO; 3];
        for (i, e) in edges.iter_mut().enumerate() {
            let (p, q) = (corners[i], corners[(i + 1) % 3]);
            // (q − p) × n points away from the third vertex for the order
            // (light, a, b), whose normal is n.
            *e = (q - p).cross(normal);
        }
        Swept { corners, min: light.min(a).min(b), max: light.max(a).max(b), normal, edges }
    }

    /// False only when the box [min, max] cannot touch the triangle: their
    /// boxes are apart, or the box lies wholly to one side of the
    /// triangle's plane or beyond one of its edges.
    fn may_touch(&self, min: DVec3, max: DVec3) -> bool {
        if min.cmpgt(self.max).any() || max.cmplt(self.min).any() {
            return false;
        }
        if self.normal == DVec3::ZERO {
            return true;
        }
        let (center, half) = (0.5 * (min + max), 0.5 * (max - min));
        let apart = |axis: DVec3, from: DVec3| {
            let reach = half.dot(axis.abs());
            axis.dot(center - from) - reach
        };
        // Wholly in front of or behind the plane.
        let reach = half.dot(self.normal.abs());
        if self.normal.dot(center - self.corners[0]).abs() > reach {
            return false;
        }
        for i in 0..3 {
            if apart(self.edges[i], self.corners[i]) > 0.0 {
                return false;
            }
        }
        true
    }
}

/// The parameters t in `range` at which the segment from o + t d to
/// `light` crosses the triangle `vertices`: the ray clipped against the
/// triangle's plane (the side away from the light) and the three planes
/// through the light and an edge (the side of the third vertex). One
/// interval or none; none when the light lies in the triangle's plane.
pub fn triangle_shadow(
    light: DVec3,
    vertices: [DVec3; 3],
    o: DVec3,
    d: DVec3,
    range: (f64, f64),
) -> Option<(f64, f64)> {
    let [a, b, c] = vertices;
    let n = (b - a).cross(c - a);
    let side = n.dot(light - a);
    if side == 0.0 || !side.is_finite() {
        return None;
    }
    let mut interval = range;
    // Beyond the plane, away from the light: −sign(side) n · (x − a) > 0.
    clip(-side.signum() * n, a, o, d, &mut interval);
    for (p, q, r) in [(a, b, c), (b, c, a), (c, a, b)] {
        let mut m = (p - light).cross(q - light);
        if m.dot(r - light) < 0.0 {
            m = -m;
        }
        clip(m, light, o, d, &mut interval);
    }
    (interval.0 < interval.1).then_some(interval)
}

/// Narrows `interval` to the t with normal · (o + t d − point) > 0.
#[inline]
fn clip(normal: DVec3, point: DVec3, o: DVec3, d: DVec3, interval: &mut (f64, f64)) {
    let start = normal.dot(o - point);
    let rate = normal.dot(d);
    if rate > 0.0 {
        interval.0 = interval.0.max(-start / rate);
    } else if rate < 0.0 {
        interval.1 = interval.1.min(-start / rate);
    } else if start <= 0.0 {
        interval.1 = interval.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SplitMix64 in [0, 1).
    fn uniform(state: &mut u64) -> f64 {
        *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Whether the segment (x, light) crosses the triangle, by Möller and
    /// Trumbore's ray–triangle test (1997): the independent answer.
    fn crosses(x: DVec3, light: DVec3, [a, b, c]: [DVec3; 3]) -> bool {
        let d = light - x;
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det == 0.0 {
            return false;
        }
        let s = x - a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let t = e2.dot(q) / det;
        u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0 && t < 1.0
    }

    #[test]
    fn triangle_shadows_and_the_hierarchy_agree_with_segment_tests() {
        // 60 random triangles, lights and rays anywhere: the union of the
        // intervals the hierarchy returns against a segment–triangle test
        // at random points of each ray, every triangle tried.
        let mut state = 5;
        let mut r = || uniform(&mut state);
        let point = |r: &mut dyn FnMut() -> f64| DVec3::new(4.0 * r() - 2.0, 4.0 * r() - 2.0, 4.0 * r() - 2.0);
        let tris: Vec<[DVec3; 3]> = (0..60)
            .map(|_| {
                let c = point(&mut r);
                let e = |r: &mut dyn FnMut() -> f64| DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5);
                [c, c + e(&mut r), c + e(&mut r)]
            })
            .collect();
        let shadows = MeshShadows::new(tris.iter().copied());
        let (mut checked, mut shadowed, mut wrong) = (0, 0, 0);
        let mut out = Vec::new();
        for _ in 0..400 {
            let light = point(&mut r);
            let o = point(&mut r);
            let d = DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize();
            out.clear();
            shadows.shadows(light, o, d, (0.0, 6.0), &mut out);
            for _ in 0..100 {
                let t = 6.0 * r();
                if out.iter().any(|&(a, b)| (t - a).abs() < 1e-9 || (t - b).abs() < 1e-9) {
                    continue;
                }
                let x = o + d * t;
                let exact = out.iter().any(|&(a, b)| t > a && t < b);
                let test = tris.iter().any(|&tri| crosses(x, light, tri));
                checked += 1;
                shadowed += test as u32;
                wrong += (exact != test) as u32;
            }
        }
        println!("triangle shadows: {checked} points, {shadowed} shadowed, {wrong} disagree");
        assert!(shadowed > checked / 10 && shadowed < checked * 9 / 10);
        assert_eq!(wrong, 0);
    }
}

//! The scene's geometry as flat primitives under one BVH (a binary tree
//! built by obvhs, collapsed into an 8-wide one (`collapse.rs`) traversed
//! with SIMD box tests (`bvh.rs`)), plus infinite planes, which no
//! bounding box holds and which are tested one by one. One ray's walk
//! through the tree is in `one_ray.rs`, packets' in `batch.rs` and
//! `packet.rs`.

use super::Ray;
use super::batch::Segment;
use super::blocks::{TriangleBlock, into_blocks};
use super::bvh::Bvh8;
use super::collapse::{CollapseCosts, TreeShape, collapse};
use super::lanes::LaneWidth;
use super::ray::offset_origin;
use super::records::{
    Instance, NO_ATTRIBUTES, PlaneRecord, Prim, Record, SdfPrim, TriangleAttributes, UNBOUNDED_FAR, UnboundedSdf,
    barycentric, intersect_plane,
};
use super::sdf::sphere_trace;
use super::shape::Shape;
use super::small::{RAYS, RayLanes, Small, small_scene};
use crate::material::Cutout;
use glam::{Mat3, Vec2, Vec3, Vec3A};
use obvhs::{BvhBuildParams, aabb::Aabb};
use std::time::Duration;

thread_local! {
    /// Shadow rays traced by this thread, for benchmarks (a thread-local
    /// counter costs about a nanosecond; a shared atomic would not scale).
    static SHADOW_RAYS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// The number of shadow rays (`occluded` calls and segments of
/// `occluded_packet` calls) this thread has traced.
pub fn shadow_rays_traced() -> u64 {
    SHADOW_RAYS.with(|n| n.get())
}

pub(super) fn count_shadow_rays(n: u64) {
    SHADOW_RAYS.with(|c| c.set(c.get() + n));
}

/// What a ray hit: its distance and which primitive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub(super) id: u32,
}

/// The local geometry at a hit point.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    pub p: Vec3,
    /// Outward geometric unit normal (for quads and planes: the normal they
    /// were given; for meshes: the winding's).
    pub n: Vec3,
    pub material: u32,
    /// The light this surface belongs to, if it is an area light's surface.
    pub emitter: Option<u32>,
    /// The primitive that was hit, for [`Geometry::uv`]: texture
    /// coordinates are found only for the surfaces whose material needs
    /// them (a quad's cost two divisions a hit: the Cornell box renders in
    /// 0.993× the time without them).
    id: u32,
}

impl SurfaceHit {
    /// The unit normal on the side that a ray along `dir` comes from.
    #[inline]
    pub fn facing(&self, dir: Vec3) -> Vec3 {
        if self.n.dot(dir) <= 0.0 { self.n } else { -self.n }
    }
}

/// All of a scene's surfaces, ready for ray queries.
#[derive(Default)]
pub struct Geometry {
    records: Vec<Record>,
    planes: Vec<PlaneRecord>,
    unbounded: Vec<UnboundedSdf>,
    /// The triangles of the tree's leaves of triangles alone, in blocks of
    /// four (the compact copy that traversal reads; empty without a tree).
    pub(super) blocks: Vec<TriangleBlock>,
    /// None when there are few primitives: testing them all is faster.
    bvh: Option<Bvh8>,
    /// A small scene of quads and a few other primitives, tested all at
    /// once for single rays instead of through `bvh` (which packets still use).
    small: Option<Small>,
    bounds: Option<(Vec3, Vec3)>,
    /// The texture coordinates of the triangles that have them.
    triangle_attributes: Vec<TriangleAttributes>,
    /// Per material index: its cut-out, if it has one ([`Geometry::set_cutouts`]).
    cutouts: Vec<Option<Cutout>>,
}

/// Up to this many primitives are tested one by one, without the BVH: the
/// fog comparison scenes (3 and 4 primitives, one a sphere enclosing the
/// rest, whose box no ray misses) render 8% and 4% faster so than through
/// the tree, with the same hits. Larger scenes take the quads' and boxes'
/// lanes ([`small::SMALL_LIMIT`](super::small::SMALL_LIMIT)) or the tree,
/// and so do scenes this small of at least half quads (a quad light's
/// surface alone, which the viewer tests packets of camera rays against).
const LINEAR_LIMIT: usize = 4;
/// Up to this many primitives, the BVH's leaves hold one primitive each.
const SMALL_SCENE: usize = 64;

impl std::fmt::Debug for Geometry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Geometry")
            .field("primitives", &self.records.len())
            .field("planes", &self.planes.len())
            .field("unbounded_sdfs", &self.unbounded.len())
            .finish()
    }
}

/// Most cut-outs a ray goes through before the next surface is taken as a
/// hit whatever it is (a ray along a stack of leaves).
const MAX_CUTOUT_LAYERS: usize = 64;

/// Collects shapes; `build` makes the BVH.
#[derive(Default)]
pub struct GeometryBuilder {
    records: Vec<Record>,
    planes: Vec<PlaneRecord>,
    unbounded: Vec<UnboundedSdf>,
    triangle_attributes: Vec<TriangleAttributes>,
}

impl GeometryBuilder {
    /// Adds a shape with a material index and, for area lights, the index of
    /// the light it is the surface of.
    pub fn add(&mut self, shape: &Shape, material: u32, emitter: Option<u32>) {
        let mut push = |prim| self.records.push(Record { prim, material, emitter, attributes: NO_ATTRIBUTES });
        match shape {
            Shape::Sphere { center, radius } => push(Prim::Sphere { center: *center, radius: *radius }),
            Shape::Quad { corner, edge_u, edge_v } => {
                push(Prim::Quad { corner: *corner, edge_u: *edge_u, edge_v: *edge_v })
            }
            Shape::Box { min, max } => push(Prim::Box { min: *min, max: *max }),
            Shape::Mesh { positions, triangles, uvs, normals } => {
                let textured = !uvs.is_empty() && uvs.len() == positions.len();
                let smooth = !normals.is_empty() && normals.len() == positions.len();
                for tri in triangles {
                    let [a, b, c] = tri.map(|i| positions[i as usize]);
                    let attributes = if textured || smooth {
                        self.triangle_attributes.push(TriangleAttributes {
                            uvs: textured.then(|| tri.map(|i| uvs[i as usize])),
                            normals: smooth.then(|| tri.map(|i| normals[i as usize])),
                        });
                        self.triangle_attributes.len() as u32 - 1
                    } else {
                        NO_ATTRIBUTES
                    };
                    let prim = Prim::Triangle { v0: a, e1: b - a, e2: c - a };
                    self.records.push(Record { prim, material, emitter, attributes });
                }
            }
            Shape::Transformed { shape, world_from_local } => {
                let prim = match shape.as_ref() {
                    Shape::Sphere { center, radius } => Prim::Sphere { center: *center, radius: *radius },
                    Shape::Box { min, max } => Prim::Box { min: *min, max: *max },
                    // Other shapes are baked by Shape::transformed.
                    other => {
                        let baked = other.clone().transformed(*world_from_local);
                        return self.add(&baked, material, emitter);
                    }
                };
                let local = prim.bounds();
                let mut bounds = Aabb::empty();
                for i in 0..8 {
                    let corner = Vec3A::new(
                        if i & 1 == 0 { local.min.x } else { local.max.x },
                        if i & 2 == 0 { local.min.y } else { local.max.y },
                        if i & 4 == 0 { local.min.z } else { local.max.z },
                    );
                    bounds.extend(world_from_local.transform_point3a(corner));
                }
                let linear = Mat3::from(world_from_local.matrix3);
                push(Prim::Instance(std::boxed::Box::new(Instance {
                    prim,
                    local_from_world: world_from_local.inverse(),
                    normal_to_world: linear.inverse().transpose(),
                    bounds,
                })))
            }
            Shape::Plane { point, normal } => {
                self.planes.push(PlaneRecord { point: *point, normal: *normal, material })
            }
            Shape::Sdf(sdf) => match sdf.bounds() {
                Some((min, max)) => push(Prim::Sdf(std::boxed::Box::new(SdfPrim { sdf: sdf.clone(), min, max }))),
                None => self.unbounded.push(UnboundedSdf { sdf: sdf.clone(), material }),
            },
        }
    }

    /// The largest number of primitives that share exactly the same
    /// bounds (duplicated faces, objects or instances): no BVH can part
    /// them, and building one over many of them takes time that grows as
    /// the square of their number.
    pub fn largest_group_of_equal_bounds(&self) -> usize {
        let mut keys: Vec<[u32; 6]> = self
            .records
            .iter()
            .map(|r| {
                let b = r.prim.bounds();
                let (lo, hi) = (Vec3::from(b.min), Vec3::from(b.max));
                [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z].map(f32::to_bits)
            })
            .collect();
        keys.sort_unstable();
        keys.chunk_by(|a, b| a == b).map(<[_]>::len).max().unwrap_or(0)
    }

    /// Builds the BVH and lays the primitives out in its order.
    pub fn build(self) -> Geometry {
        let GeometryBuilder { records, planes, unbounded, triangle_attributes } = self;
        let bounds = records.iter().map(|r| r.prim.bounds()).reduce(|a, b| a.union(&b));
        let bounds = bounds.map(|b| (Vec3::from(b.min), Vec3::from(b.max)));
        // Without a tree, every primitive is tested for every ray.
        if records.len() <= LINEAR_LIMIT {
            let small = small_scene(&records);
            return Geometry { records, planes, unbounded, bounds, triangle_attributes, small, ..Geometry::default() };
        }
        // A binary tree of one primitive a leaf, from which the collapse
        // chooses the leaves. obvhs's second reinsertion pass (run after
        // its own leaf collapse, which leaves of one skip) is skipped too:
        // on a 1.1 M-triangle mesh it made the build take 1.6× as long,
        // for rays one at a time 1–4% faster (BENCHMARKS.md).
        let mut params = BvhBuildParams::medium_build();
        params.max_prims_per_leaf = 1;
        params.post_collapse_reinsertion_batch_ratio_multiplier = 0.0;
        let bvh2 = obvhs::bvh2::builder::build_bvh2(&records, params, &mut Duration::default());
        let costs = if records.len() <= SMALL_SCENE {
            // One primitive per leaf: in a room of a few quads and boxes the
            // boxes' SIMD test spares most primitive tests, where a leaf of
            // several would test them all.
            CollapseCosts { max_leaf: 1, ..CollapseCosts::MESH }
        } else {
            CollapseCosts::MESH
        };
        let is_triangle = |i: u32| matches!(records[i as usize].prim, Prim::Triangle { .. });
        let (mut bvh, order) = collapse::<8>(&bvh2, is_triangle, &costs);
        // Reorder so that the tree's leaf ranges index `records` directly.
        let records: Vec<Record> =
            super::pages::collect_in_huge_pages(order.iter().map(|&i| records[i as usize].clone()));
        // Many primitives with the same bounds (duplicated objects or faces)
        // can make the tree deeper than the traversal's fixed stack: such
        // scenes are searched linearly instead, slow but right.
        if bvh.depth() > Bvh8::MAX_DEPTH {
            return Geometry { records, planes, unbounded, bounds, triangle_attributes, ..Geometry::default() };
        }
        let blocks = into_blocks(&mut bvh, &records);
        let small = small_scene(&records);
        Geometry {
            records,
            planes,
            unbounded,
            blocks,
            bvh: Some(bvh),
            small,
            bounds,
            triangle_attributes,
            cutouts: Vec::new(),
        }
    }
}

impl Geometry {
    /// The tree's shape and its cost by the surface area heuristic, if the
    /// geometry has a tree: for benchmarks.
    #[doc(hidden)]
    pub fn tree_shape(&self) -> Option<TreeShape> {
        self.bvh.as_ref().map(TreeShape::of)
    }

    /// Number of bounded primitives (triangles count one each) and of
    /// unbounded ones (planes, SDFs holding a plane).
    pub fn primitive_count(&self) -> (usize, usize) {
        (self.records.len(), self.planes.len() + self.unbounded.len())
    }

    /// Bounds of everything but the infinite planes, or None if there is nothing.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.bounds
    }

    /// The nearest hit with 0 < t < tmax.
    pub fn intersect(&self, ray: &Ray, tmax: f32) -> Option<Hit> {
        self.intersect_on(LaneWidth::widest(), ray, tmax)
    }

    /// Gives the materials' cut-outs, by material index: hits on them where
    /// rays pass ([`Cutout::passes`]) are gone through.
    pub fn set_cutouts(&mut self, cutouts: Vec<Option<Cutout>>) {
        self.cutouts = if cutouts.iter().any(Option::is_some) { cutouts } else { Vec::new() };
    }

    /// Whether some material is cut out.
    pub fn has_cutouts(&self) -> bool {
        !self.cutouts.is_empty()
    }

    /// Whether `ray` goes through the hit `hit` (a cut-out open there).
    fn passes(&self, ray: &Ray, hit: Hit) -> bool {
        let Some(rec) = self.records.get(hit.id as usize) else { return false };
        let Some(Some(cutout)) = self.cutouts.get(rec.material as usize) else { return false };
        let p = ray.at(hit.t);
        // The ray's own number for a blend: a hash of where it meets the
        // surface and where it goes, the same on every run.
        let bits = |v: Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        let [a, b, c] = bits(p);
        let [d, e, f] = bits(ray.dir);
        let key = ((a as u64) << 32 | b as u64) ^ ((c as u64) << 32 | d as u64).rotate_left(17);
        let u = crate::sampling::keyed2(key, (e as u64) << 32 | f as u64).x;
        cutout.passes(self.uv_at(rec, p), u)
    }

    /// The nearest hit not in a cut-out's open part: the nearest hit, and
    /// while a cut-out lets the ray through there, the nearest beyond it
    /// from just past the surface (at most [`MAX_CUTOUT_LAYERS`] times; the
    /// last is then taken as a hit).
    fn through_cutouts(&self, ray: &Ray, tmax: f32, nearest: impl Fn(&Ray, f32) -> Option<Hit>) -> Option<Hit> {
        let mut from = *ray;
        for _ in 0..MAX_CUTOUT_LAYERS {
            let hit = nearest(&from, tmax - (from.origin - ray.origin).dot(ray.dir))?;
            let total = Hit { t: (from.origin - ray.origin).dot(ray.dir) + hit.t, id: hit.id };
            if !self.passes(&from, hit) {
                return Some(total);
            }
            let p = from.at(hit.t);
            let n = self.records[hit.id as usize].prim.normal(p);
            from = Ray::new(offset_origin(p, n, ray.dir), ray.dir);
        }
        nearest(&from, tmax - (from.origin - ray.origin).dot(ray.dir))
            .map(|hit| Hit { t: (from.origin - ray.origin).dot(ray.dir) + hit.t, id: hit.id })
    }

    /// [`Geometry::intersect`] with the tree's box and triangle tests on
    /// the given lanes, which the processor must have
    /// ([`LaneWidth::available`]; panics if not): for tests. One ray goes
    /// at most eight lanes wide (`Sixteen` takes eight).
    #[doc(hidden)]
    pub fn intersect_on(&self, lanes: LaneWidth, ray: &Ray, tmax: f32) -> Option<Hit> {
        if self.has_cutouts() {
            return self.through_cutouts(ray, tmax, |r, t| self.intersect_opaque_on(lanes, r, t));
        }
        self.intersect_opaque_on(lanes, ray, tmax)
    }

    /// [`Geometry::intersect_on`] with every surface opaque.
    fn intersect_opaque_on(&self, lanes: LaneWidth, ray: &Ray, tmax: f32) -> Option<Hit> {
        let mut best = Hit { t: tmax, id: u32::MAX };
        if let Some(small) = &self.small {
            small.nearest(&self.records, ray.origin, ray.dir, tmax, &mut best);
        } else {
            match &self.bvh {
                Some(bvh) => {
                    let found = self.nearest_in_tree(lanes, bvh, ray.origin, ray.dir, tmax);
                    if let Some((t, id)) = found {
                        best = Hit { t, id };
                    }
                }
                None => {
                    for (i, rec) in self.records.iter().enumerate() {
                        let t = rec.prim.intersect(ray.origin, ray.dir, 0.0, best.t);
                        if t < best.t {
                            best = Hit { t, id: i as u32 };
                        }
                    }
                }
            }
        }
        self.intersect_unbounded(ray, &mut best);
        (best.id != u32::MAX).then_some(best)
    }

    /// `hits[i]` = `self.intersect(&rays[i], tmax[i])`, bit for bit, with
    /// each ray's own bound: a small scene's rays eight at a time, each
    /// quad and box against all eight at once; other scenes' one by one.
    pub fn intersect_each(&self, rays: &[Ray], tmax: &[f32], hits: &mut [Option<Hit>]) {
        assert!(rays.len() == tmax.len() && rays.len() == hits.len(), "one bound and one hit slot per ray");
        match &self.small {
            Some(small) if !self.has_cutouts() => self.intersect_small_packets(small, rays, |i| tmax[i], hits),
            _ => {
                for ((ray, &tmax), hit) in rays.iter().zip(tmax).zip(hits.iter_mut()) {
                    *hit = self.intersect(ray, tmax);
                }
            }
        }
    }

    /// The small scene's side of [`Geometry::intersect_packet`] and
    /// [`Geometry::intersect_each`]: `hits[i]` = `self.intersect(&rays[i], tmax(i))`.
    pub(super) fn intersect_small_packets(
        &self,
        small: &Small,
        rays: &[Ray],
        tmax: impl Fn(usize) -> f32,
        hits: &mut [Option<Hit>],
    ) {
        for (start, (rays, hits)) in (0..).step_by(RAYS).zip(rays.chunks(RAYS).zip(hits.chunks_mut(RAYS))) {
            let lanes = RayLanes::new(rays.iter().enumerate().map(|(k, r)| (r.origin, r.dir, tmax(start + k))));
            let (mut best_t, mut best_id) = (lanes.tmax, [u32::MAX; RAYS]);
            small.nearest_packet(&self.records, &lanes, &mut best_t, &mut best_id);
            for (k, (ray, hit)) in rays.iter().zip(hits.iter_mut()).enumerate() {
                let mut best = Hit { t: best_t[k], id: best_id[k] };
                self.intersect_unbounded(ray, &mut best);
                *hit = (best.id != u32::MAX).then_some(best);
            }
        }
    }

    /// The small scene's side of [`Geometry::occluded_packet`]: `blocked[i]`
    /// is set where something blocks `segments[i]` (the unbounded
    /// primitives already tested by the caller).
    pub(super) fn occluded_small_packets(&self, small: &Small, segments: &[Segment], blocked: &mut [bool]) {
        for (segments, blocked) in segments.chunks(RAYS).zip(blocked.chunks_mut(RAYS)) {
            // Segments already blocked need no test: an empty lane.
            let lanes = RayLanes::new(
                segments.iter().zip(blocked.iter()).map(|(s, &b)| (s.origin, s.dir, if b { 0.0 } else { s.tmax })),
            );
            let mut found = [false; RAYS];
            small.any_packet(&self.records, &lanes, &mut found);
            for (b, found) in blocked.iter_mut().zip(found) {
                *b |= found;
            }
        }
    }

    /// Planes and unbounded SDFs, tested one by one after the bounded primitives.
    pub(super) fn intersect_unbounded(&self, ray: &Ray, best: &mut Hit) {
        let base = self.records.len() as u32;
        for (i, plane) in self.planes.iter().enumerate() {
            let t = intersect_plane(plane, ray.origin, ray.dir);
            if t > 0.0 && t < best.t {
                *best = Hit { t, id: base + i as u32 };
            }
        }
        let base = base + self.planes.len() as u32;
        for (i, u) in self.unbounded.iter().enumerate() {
            let t = sphere_trace(&u.sdf, ray.origin, ray.dir, 0.0, best.t.min(UNBOUNDED_FAR));
            if t > 0.0 && t < best.t {
                *best = Hit { t, id: base + i as u32 };
            }
        }
    }

    /// Whether anything lies on the open segment `origin + t·dir`, 0 < t < tmax.
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        self.occluded_on(LaneWidth::widest(), origin, dir, tmax)
    }

    /// [`Geometry::occluded`] with the tree's box tests on the given lanes,
    /// as [`Geometry::intersect_on`]: for tests.
    #[doc(hidden)]
    pub fn occluded_on(&self, lanes: LaneWidth, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        count_shadow_rays(1);
        if self.occluded_unbounded(origin, dir, tmax) {
            return true;
        }
        if self.has_cutouts() {
            // Any hit may be an open part of a cut-out: the nearest, in turn.
            let ray = Ray::new(origin, dir);
            return self.through_cutouts(&ray, tmax, |r, t| self.intersect_opaque_on(lanes, r, t)).is_some();
        }
        if let Some(small) = &self.small {
            return small.any(&self.records, origin, dir, tmax);
        }
        match &self.bvh {
            Some(bvh) => self.blocked_in_tree(lanes, bvh, origin, dir, tmax),
            None => self.occluded_linear(origin, dir, tmax),
        }
    }

    /// Whether a bounded primitive blocks the segment, testing them all.
    pub(super) fn occluded_linear(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        self.records.iter().any(|rec| rec.prim.intersect(origin, dir, 0.0, tmax) < tmax)
    }

    /// The tree, if the scene has one.
    pub(super) fn bvh(&self) -> Option<&Bvh8> {
        self.bvh.as_ref()
    }

    /// The quads' and boxes' lanes, if the scene is small enough for them.
    pub(super) fn small(&self) -> Option<&Small> {
        self.small.as_ref()
    }

    /// Whether a plane or unbounded SDF blocks the segment.
    pub(super) fn occluded_unbounded(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        for plane in &self.planes {
            let t = intersect_plane(plane, origin, dir);
            if t > 0.0 && t < tmax {
                return true;
            }
        }
        for u in &self.unbounded {
            let t = sphere_trace(&u.sdf, origin, dir, 0.0, tmax.min(UNBOUNDED_FAR));
            if t > 0.0 && t < tmax {
                return true;
            }
        }
        false
    }

    /// Record `i`'s hit distance in (0, tmax), or infinity, by its own
    /// primitive's test: for leaves that hold something other than
    /// triangles (leaves of triangles alone go several at a time in lanes,
    /// from the compact copies).
    #[inline(always)]
    pub(super) fn intersect_one(&self, i: usize, o: Vec3, d: Vec3, tmax: f32) -> f32 {
        self.records[i].prim.intersect(o, d, 0.0, tmax)
    }

    /// Whether any primitive is a signed distance field.
    pub fn has_sdf(&self) -> bool {
        self.records.iter().any(|rec| matches!(rec.prim, Prim::Sdf(_)))
    }

    /// The nearest hit found by testing every primitive: the oracle that the
    /// BVH is tested against.
    pub fn intersect_brute_force(&self, ray: &Ray, tmax: f32) -> Option<Hit> {
        let mut best = Hit { t: tmax, id: u32::MAX };
        for (i, rec) in self.records.iter().enumerate() {
            let t = rec.prim.intersect(ray.origin, ray.dir, 0.0, best.t);
            if t < best.t {
                best = Hit { t, id: i as u32 };
            }
        }
        self.intersect_unbounded(ray, &mut best);
        (best.id != u32::MAX).then_some(best)
    }

    /// The surface at a hit of `ray`.
    pub fn surface(&self, ray: &Ray, hit: Hit) -> SurfaceHit {
        let p = ray.at(hit.t);
        let (index, id) = (hit.id as usize, hit.id);
        match self.records.get(index) {
            Some(rec) => {
                let known = self.small.as_ref().and_then(|s| s.known_normal(index, &rec.prim, p));
                let n = known.unwrap_or_else(|| rec.prim.normal(p));
                SurfaceHit { p, n, material: rec.material, emitter: rec.emitter, id }
            }
            None => match self.planes.get(index - self.records.len()) {
                Some(plane) => SurfaceHit { p, n: plane.normal, material: plane.material, emitter: None, id },
                None => {
                    let u = &self.unbounded[index - self.records.len() - self.planes.len()];
                    SurfaceHit { p, n: u.sdf.normal(p), material: u.material, emitter: None, id }
                }
            },
        }
    }

    /// Texture coordinates at a surface point: a mesh's that has them,
    /// interpolated; a quad's (α, 1 − β) for the point corner + α·edge_u +
    /// β·edge_v (the image upright when edge_u points right and edge_v up);
    /// None elsewhere.
    pub fn uv(&self, surface: &SurfaceHit) -> Option<Vec2> {
        self.records.get(surface.id as usize).and_then(|rec| self.uv_at(rec, surface.p))
    }

    /// The shading normal at a surface point: a mesh's vertex normals
    /// interpolated, normalised; None elsewhere (and where they cancel).
    pub fn vertex_normal(&self, surface: &SurfaceHit) -> Option<Vec3> {
        let rec = self.records.get(surface.id as usize)?;
        let Prim::Triangle { v0, e1, e2 } = rec.prim else { return None };
        if rec.attributes == NO_ATTRIBUTES {
            return None;
        }
        let [n0, n1, n2] = self.triangle_attributes[rec.attributes as usize].normals?;
        let [b1, b2] = barycentric(surface.p - v0, e1, e2);
        (n0 * (1.0 - b1 - b2) + n1 * b1 + n2 * b2).try_normalize()
    }

    /// How the surface moves with its texture coordinates at a hit, ∂p/∂u
    /// and ∂p/∂v (constant over a triangle; a quad's are its edges, u
    /// along edge_u and v against edge_v); None without texture
    /// coordinates or where they do not span the triangle.
    pub fn uv_derivatives(&self, surface: &SurfaceHit) -> Option<(Vec3, Vec3)> {
        let rec = self.records.get(surface.id as usize)?;
        match rec.prim {
            Prim::Triangle { e1, e2, .. } if rec.attributes != NO_ATTRIBUTES => {
                let [t0, t1, t2] = self.triangle_attributes[rec.attributes as usize].uvs?;
                let (d1, d2) = (t1 - t0, t2 - t0);
                let det = d1.x * d2.y - d1.y * d2.x;
                if det == 0.0 || !det.is_finite() {
                    return None;
                }
                let dpdu = (e1 * d2.y - e2 * d1.y) / det;
                let dpdv = (e2 * d1.x - e1 * d2.x) / det;
                (dpdu.is_finite() && dpdv.is_finite()).then_some((dpdu, dpdv))
            }
            Prim::Quad { edge_u, edge_v, .. } => Some((edge_u, -edge_v)),
            _ => None,
        }
    }

    /// The texture coordinates at point `p` of a record (see [`SurfaceHit::uv`]).
    fn uv_at(&self, rec: &Record, p: Vec3) -> Option<Vec2> {
        match rec.prim {
            Prim::Triangle { v0, e1, e2 } if rec.attributes != NO_ATTRIBUTES => {
                let [t0, t1, t2] = self.triangle_attributes[rec.attributes as usize].uvs?;
                let [b1, b2] = barycentric(p - v0, e1, e2);
                Some(t0 + (t1 - t0) * b1 + (t2 - t0) * b2)
            }
            Prim::Quad { corner, edge_u, edge_v } => {
                let [alpha, beta] = barycentric(p - corner, edge_u, edge_v);
                Some(Vec2::new(alpha, 1.0 - beta))
            }
            _ => None,
        }
    }
}

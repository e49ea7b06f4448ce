//! Radiosity global illumination with a patch hierarchy, after Madams
//! (Tom Madams's blog post on real-time radiosity, 2011).
//!
//! A static scene is compiled once ([`Radiosity::compile`]): its surfaces are
//! cut into patches ([`patches`]), the patches clustered into a hierarchy
//! ([`hierarchy`]), and each patch linked to the patches and clusters it sees
//! with their form factors ([`links`]). Then every frame
//! ([`Radiosity::update`]) computes the direct irradiance E⁰ on each patch,
//! pushes the radiosity B = ρ·E up the hierarchy (area-weighted) and gathers
//! one bounce over the links:
//!
//!   E¹_i = Σ_j F_ij B⁰_j,  B⁰_j = ρ_j E⁰_j,
//!
//! Madams's I_i = Σ_j D_j F_ij with D_j = ρ_j E⁰_j. `bounces = N` repeats
//! push and gather N times (Eᵏ⁺¹_i = Σ_j F_ij ρ_j Eᵏ_j, a Jacobi iteration of
//! the radiosity equation, Cohen and Wallace 1993 §5), and the indirect
//! irradiance kept per patch is E¹ + … + E^N. Moving a light, changing its
//! intensity or a material's albedo needs only `update`, not a recompile.
//!
//! Conventions: E is irradiance (W/m²); a Lambertian surface of albedo ρ
//! reflects radiance L = ρE/π, and its radiosity (exitance) is B = πL = ρE.
//! The integrator ([`crate::integrator::RadiosityIntegrator`]) evaluates
//! direct light per pixel and adds the indirect part ρ(p)/π · E_ind(p), with
//! E_ind interpolated between patch centres ([`lookup`]): Madams's "direct
//! and indirect illumination at different frequencies". Patches exchange
//! light in vacuum; a medium attenuates only the camera ray and the per-pixel
//! direct light. The diffuse albedo of a Phong material bounces; its specular
//! lobe does not.

pub mod enclosures;
pub mod factors;
pub mod hierarchy;
pub mod lighting;
pub mod links;
pub mod lookup;
pub mod patches;

use crate::Rgb;
use crate::material::Material;
use crate::scene::Scene;
use glam::Vec3;
use hierarchy::Hierarchy;
use links::Links;
use lookup::Lookup;
use patches::Patch;
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Most patches a scene may be cut into (about 4 GB of links with patches
/// alone receiving at the default threshold; see docs/radiosity-bench.md).
pub const MAX_PATCHES: usize = 2_000_000;

/// Peak bytes of compilation per patch, for the up-front memory check,
/// with patches alone receiving (the most links): ~340 packed links of 6
/// bytes, patch and cluster records, and one block's unpacked links
/// (docs/radiosity-bench.md). Clusters receiving at
/// [`LARGE_RECEIVER_SHARE`] peak at a fifth of this (554 MB at 1M patches).
pub const PEAK_BYTES_PER_PATCH: u64 = 4 << 10;

/// Scenes estimated to cut into more patches than this (both sides of
/// boxes counted, before culling) let clusters receive by default, with
/// [`LARGE_RECEIVER_SHARE`]; smaller ones keep patch-only receivers.
pub const RECEIVER_CLUSTERS_FROM: f64 = 100_000.0;

/// The default receiver share of large scenes. With patches alone as
/// receivers each patch keeps ~340 links however fine the cut (341 M links,
/// 2 GB, at 1M patches on the Cornell box); with flat clusters receiving
/// at 0.1, a patch's far field is shared by its neighbours: 93 links per
/// patch at 100k, for an area-weighted mean difference of 2.5% in the
/// one-bounce irradiance from the patch-only solution (the hierarchy
/// itself differs by 1.8% from the full O(N²) one); see
/// docs/radiosity-bench.md. Below [`RECEIVER_CLUSTERS_FROM`] receiver
/// clusters save little (at 7k patches, 0.1 saves a fifth of the links
/// for a 1.1% difference) and are left off.
pub const LARGE_RECEIVER_SHARE: f32 = 0.1;

/// Why a scene cannot be compiled.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RadiosityError {
    #[error("radiosity: {0}; choose a larger render.patch_size")]
    Memory(#[from] crate::memory::MemoryError),
    #[error(
        "render.patch_size = {patch_size} would cut the scene into about {estimated} patches; \
         at most {MAX_PATCHES} are allowed: choose a larger patch_size"
    )]
    TooManyPatches { patch_size: f32, estimated: f64 },
}

/// How many patches `scene` cuts into at `patch_size`, counting both sides
/// of boxes and spheres (before culling), without cutting it.
pub fn estimated_patches(scene: &Scene, patch_size: f32) -> f64 {
    let square = scene.bounds();
    scene.objects().iter().map(|(shape, _)| patches::count(shape, patch_size, square)).sum()
}

thread_local! {
    /// Solutions compiled by this thread (thread-local, so that tests
    /// running side by side do not see each other's).
    static COMPILES: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// What compilation needs beyond the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompileParams {
    /// Longest patch edge, world units.
    pub patch_size: f32,
    /// A cluster becomes one link when its estimated form factor
    /// A/(π d²) is below this (and the receiver lies outside twice its
    /// bounding radius); 0 links every patch to every patch it sees.
    pub link_threshold: f32,
    /// Clusters may receive light too (Hanrahan, Salzman and Aupperle's
    /// two-sided refinement) when flat (normals within ~18°) and their own
    /// estimated form factor is below `receiver_share × link_threshold`; the
    /// irradiance a cluster gathers is handed down to its patches. 0 lets
    /// only patches receive, as Madams does: the default up to
    /// [`RECEIVER_CLUSTERS_FROM`] patches, where receiver clusters save
    /// fewer links than they cost in accuracy; larger scenes default to
    /// [`LARGE_RECEIVER_SHARE`].
    pub receiver_share: f32,
    /// Seeds the clustering and the sample positions.
    pub seed: u64,
}

impl CompileParams {
    /// The integrator's options for `scene`; without `patch_size`, 1/32 of
    /// the largest extent of the bounded geometry (1/16 of the scene's
    /// bounding radius when there are only planes). Seeded by the scene's
    /// seed. Clusters receive ([`LARGE_RECEIVER_SHARE`]) when the scene
    /// cuts into more than [`RECEIVER_CLUSTERS_FROM`] patches.
    pub fn for_scene(scene: &Scene, options: &RadiosityOptions) -> Self {
        let patch_size = options.patch_size.unwrap_or_else(|| match scene.geometry().bounds() {
            Some((lo, hi)) if (hi - lo).max_element() > 0.0 => (hi - lo).max_element() / 32.0,
            _ => scene.bounds().1 / 16.0,
        });
        let large = estimated_patches(scene, patch_size) > RECEIVER_CLUSTERS_FROM;
        CompileParams {
            patch_size,
            link_threshold: options.link_threshold,
            receiver_share: if large { LARGE_RECEIVER_SHARE } else { 0.0 },
            seed: scene.settings().seed,
        }
    }
}

/// Default of [`RadiosityOptions::link_threshold`].
pub const DEFAULT_LINK_THRESHOLD: f32 = 0.02;

/// The radiosity integrator's options (`[render]` patch_size, bounces,
/// link_threshold): patches, links and bounces. In a medium its camera
/// rays are marched with the raymarch options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadiosityOptions {
    /// Side length (world units) surfaces are cut into patches of; None
    /// picks 1/32 of the largest extent of the bounded geometry.
    pub patch_size: Option<f32>,
    /// Bounces of indirect light (1 = one bounce, as in Madams technique).
    pub bounces: u32,
    /// A patch links to a whole cluster instead of its children when the
    /// cluster's estimated form factor A/(π d²) is below this; 0 links
    /// every patch to every patch it sees (the O(N²) solution).
    pub link_threshold: f32,
}

impl Default for RadiosityOptions {
    fn default() -> Self {
        RadiosityOptions { patch_size: None, bounces: 1, link_threshold: DEFAULT_LINK_THRESHOLD }
    }
}

/// What compilation made and what it cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CompileStats {
    pub patches: usize,
    /// Patch sides dropped because nothing lies in front of them (see
    /// [`patches::faces_anything`]).
    pub dropped: usize,
    pub clusters: usize,
    pub links: usize,
    /// Links between two single patches (the rest have a cluster at one end
    /// or both).
    pub links_patch_to_patch: usize,
    /// Bytes held by patches, hierarchy, links, lookup grid and per-frame
    /// buffers.
    pub bytes: usize,
    pub cut: Duration,
    pub cull: Duration,
    pub cluster: Duration,
    pub link: Duration,
    pub total: Duration,
}

/// Time spent in one [`Radiosity::update`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameTimes {
    pub direct: Duration,
    pub push: Duration,
    pub gather: Duration,
}

impl FrameTimes {
    pub fn total(&self) -> Duration {
        self.direct + self.push + self.gather
    }
}

/// A compiled scene and its current lighting.
#[derive(Clone, Debug)]
pub struct Radiosity {
    params: CompileParams,
    patches: Vec<Patch>,
    hierarchy: Hierarchy,
    links: Links,
    lookup: Lookup,
    stats: CompileStats,
    /// Per patch: albedo (from the materials last seen), direct irradiance,
    /// indirect irradiance summed over bounces.
    albedo: Vec<Rgb>,
    materials: Vec<Material>,
    direct: Vec<Rgb>,
    indirect: Vec<Rgb>,
    /// Per node (patches, then clusters): area, for pushing radiosity up.
    node_area: Vec<f32>,
    /// Per node: radiosity (16-byte aligned for the gather's SIMD).
    node_b: Vec<glam::Vec3A>,
    /// Per node: one bounce's gathered irradiance.
    gathered: Vec<Rgb>,
}

impl Radiosity {
    /// Compiles `scene` with `options`, then lights it with its lights
    /// ([`Radiosity::update`]).
    pub fn compile(scene: &Scene, options: &RadiosityOptions) -> Result<Radiosity, RadiosityError> {
        let mut r = Radiosity::compile_with(scene, CompileParams::for_scene(scene, options))?;
        r.update(scene, options.bounces);
        Ok(r)
    }

    /// How many solutions this thread has compiled (for tests that check
    /// that animations relight instead of recompiling).
    pub fn compile_count() -> usize {
        COMPILES.with(|c| c.get())
    }

    /// Compiles `scene` (cut, cull, cluster, link); the lighting is zero
    /// until [`Radiosity::update`]. Fails, before cutting, when the patch
    /// size would make more than [`MAX_PATCHES`] patches.
    pub fn compile_with(scene: &Scene, params: CompileParams) -> Result<Radiosity, RadiosityError> {
        COMPILES.with(|c| c.set(c.get() + 1));
        let start = Instant::now();
        let mut patches = Vec::new();
        let square = scene.bounds();
        let estimated = estimated_patches(scene, params.patch_size);
        if estimated.is_nan() || estimated > MAX_PATCHES as f64 {
            return Err(RadiosityError::TooManyPatches { patch_size: params.patch_size, estimated });
        }
        let what = format!("compiling about {} patches (patch_size {})", estimated.round(), params.patch_size);
        crate::memory::check(what, estimated as u64 * PEAK_BYTES_PER_PATCH)?;
        for (index, (shape, material)) in scene.objects().iter().enumerate() {
            let inner = enclosures::holds_light(shape, scene.lights(), scene.light_paths());
            patches::cut(shape, *material, index as u32, params.patch_size, square, inner, &mut patches);
        }
        let cut = start.elapsed();

        let t = Instant::now();
        let extents: Vec<patches::Extent> =
            scene.objects().iter().map(|(shape, _)| patches::Extent::of(shape)).collect();
        let keep: Vec<bool> = patches.par_iter().map(|p| patches::faces_anything(p, &extents)).collect();
        let before = patches.len();
        let mut keep = keep.into_iter();
        patches.retain(|_| keep.next().unwrap_or(false));
        let dropped = before - patches.len();
        let cull = t.elapsed();

        let t = Instant::now();
        let hierarchy = hierarchy::build(&mut patches, params.seed);
        let cluster = t.elapsed();

        let t = Instant::now();
        // Area lights' surfaces block links too (the Cornell box's light
        // shades the ceiling above it from bounce light: 6% of that wall's
        // one-bounce light). Links are made once, so when such a light moves
        // the shadow it casts on bounce light stays where it was compiled.
        let links = links::build(
            &patches,
            &hierarchy,
            scene.geometry(),
            params.link_threshold,
            params.receiver_share,
            params.seed,
        );
        let link = t.elapsed();
        let lookup = Lookup::build(&patches, 1.5 * params.patch_size);

        let n = patches.len();
        let nodes = n + hierarchy.clusters.len();
        let mut r = Radiosity {
            params,
            stats: CompileStats::default(),
            albedo: vec![Rgb::ZERO; n],
            materials: Vec::new(),
            direct: vec![Rgb::ZERO; n],
            indirect: vec![Rgb::ZERO; n],
            node_area: patches.iter().map(|p| p.area).chain(hierarchy.clusters.iter().map(|c| c.area)).collect(),
            node_b: vec![glam::Vec3A::ZERO; nodes],
            gathered: vec![Rgb::ZERO; nodes],
            patches,
            hierarchy,
            links,
            lookup,
        };
        r.stats = CompileStats {
            patches: n,
            dropped,
            clusters: r.hierarchy.clusters.len(),
            links: r.links.len(),
            links_patch_to_patch: r.links.patch_to_patch,
            bytes: r.bytes(),
            cut,
            cull,
            cluster,
            link,
            total: start.elapsed(),
        };
        Ok(r)
    }

    fn bytes(&self) -> usize {
        let per_patch = self.patches.capacity() * size_of::<Patch>()
            + (self.albedo.capacity() + self.direct.capacity() + self.indirect.capacity() + self.gathered.capacity())
                * size_of::<Rgb>()
            + self.node_b.capacity() * size_of::<glam::Vec3A>()
            + self.node_area.capacity() * size_of::<f32>();
        per_patch + self.hierarchy.bytes() + self.links.bytes() + self.lookup.bytes()
    }

    /// The per-frame step with the scene's lights and materials (anything
    /// but the geometry may have changed since compiling): direct light,
    /// then `bounces` × (push, gather). The inner sides of boxes and spheres
    /// were patched when compiling for the scene's lights inside them along
    /// their keyframe paths ([`enclosures`]); a light moved into a closed
    /// shape that held none lights its inside directly, with no bounce.
    pub fn update(&mut self, scene: &Scene, bounces: u32) -> FrameTimes {
        if self.materials != scene.materials() {
            self.materials = scene.materials().to_vec();
            for (a, p) in self.albedo.iter_mut().zip(&self.patches) {
                *a = scene.material(p.material).albedo(p.center, p.normal);
            }
        }
        let mut times = FrameTimes::default();
        let t = Instant::now();
        lighting::direct(scene, &self.patches, self.params.seed, &mut self.direct);
        times.direct = t.elapsed();

        let n = self.patches.len();
        self.indirect.fill(Rgb::ZERO);
        for bounce in 0..bounces {
            let t = Instant::now();
            let source = if bounce == 0 { &self.direct } else { &self.gathered };
            for ((b, a), e) in self.node_b[..n].iter_mut().zip(&self.albedo).zip(source) {
                *b = (*a * *e).into();
            }
            lighting::push(&self.node_area, &self.hierarchy, &mut self.node_b);
            times.push += t.elapsed();
            let t = Instant::now();
            lighting::gather(&self.links, &self.node_b, &mut self.gathered);
            lighting::push_down(&self.hierarchy, n, &mut self.gathered);
            for (e, g) in self.indirect.iter_mut().zip(&self.gathered) {
                *e += *g;
            }
            times.gather += t.elapsed();
        }
        times
    }

    /// The indirect irradiance at `p` on the side with unit normal `n`,
    /// interpolated smoothly between patch centres ([`lookup`]); None where
    /// no patch is near (a side dropped as seeing nothing).
    pub fn irradiance_at(&self, p: Vec3, n: Vec3) -> Option<Rgb> {
        self.lookup.interpolate(&self.patches, p, n, |i| self.indirect[i])
    }

    /// [`Radiosity::irradiance_at`] from the patches that `p` sees in
    /// `geometry`: a point near a wall does not take the light of patches
    /// on its other side (a floor that runs under a wall into the sun). It
    /// costs a shadow ray per nearby patch; the viewer's preview does
    /// without.
    pub fn irradiance_seen_at(&self, p: Vec3, n: Vec3, geometry: &crate::geometry::Geometry) -> Option<Rgb> {
        // The path from p to a patch's centre runs just above the surface
        // (lifted by ε at both ends), bent at its middle over a curved one: a
        // ball's chord dips below its surface by d·θ/8 (θ the angle between
        // the two normals), so the middle is lifted by twice that. A wall
        // between them, or the far face of a thin slab, still stops it.
        let epsilon = 1e-3 * self.lookup.radius();
        let clear = |a: Vec3, b: Vec3| {
            let to = b - a;
            let length = to.length();
            length <= 0.0 || !geometry.occluded(a, to / length, length * (1.0 - 1e-4))
        };
        let sees = |i: usize| {
            let patch = &self.patches[i];
            let (from, to) = (p + n * epsilon, patch.center + patch.normal * epsilon);
            let angle = n.dot(patch.normal).clamp(-1.0, 1.0).acos();
            let up = (n + patch.normal).normalize_or(n);
            let middle = 0.5 * (from + to) + up * (0.25 * angle * from.distance(to) + epsilon);
            clear(from, middle) && clear(middle, to)
        };
        self.lookup.interpolate_where(&self.patches, p, n, sees, |i| self.indirect[i])
    }

    pub fn params(&self) -> CompileParams {
        self.params
    }
    pub fn stats(&self) -> CompileStats {
        self.stats
    }
    pub fn patches(&self) -> &[Patch] {
        &self.patches
    }
    pub fn hierarchy(&self) -> &Hierarchy {
        &self.hierarchy
    }
    pub fn links(&self) -> &Links {
        &self.links
    }
    /// The grid that [`Radiosity::irradiance_at`] interpolates with.
    pub fn lookup(&self) -> &Lookup {
        &self.lookup
    }
    /// Direct irradiance per patch from the last update.
    pub fn direct_irradiance(&self) -> &[Rgb] {
        &self.direct
    }
    /// Indirect irradiance per patch (all bounces) from the last update.
    pub fn indirect_irradiance(&self) -> &[Rgb] {
        &self.indirect
    }
}

#[cfg(test)]
mod tests;

//! The Rust scene and the integrator last built for it, which the Python
//! scenes that `at_time` and `frame` make from one another share, as the
//! CLI's animations do: the integrator is built once for the lights as the
//! file writes them, and a render at another time only moves the lights
//! and tells the integrator (radiosity relights instead of recompiling).

use airlight::integrator::{Integrator, IntegratorDesc, IntegratorError};
use airlight::light::Light;
use airlight::scene::Scene;

/// Where the lights are: None as the file writes them (a still render),
/// Some(t) at time t of the keyframes.
pub type Pose = Option<f32>;

/// The Rust scene and its integrator, shared by the scenes `at_time` makes.
pub struct Shared {
    pub scene: Scene,
    /// The lights as the file writes them.
    base_lights: Vec<Light>,
    /// The pose the scene's lights are in; None while unknown (a panic
    /// part way through moving them).
    pose: Option<Pose>,
    cache: Option<Cached>,
}

/// The integrator last built, what it was built from, and the pose it was
/// last told of (None: unknown).
struct Cached {
    desc: IntegratorDesc,
    /// Radiosity draws its patches' samples with the scene's seed.
    seed: u64,
    integrator: Box<dyn Integrator>,
    pose: Option<Pose>,
}

impl Shared {
    pub fn new(scene: Scene) -> Shared {
        Shared { base_lights: scene.lights().to_vec(), scene, pose: Some(None), cache: None }
    }

    /// After a panic while the scene was held: rebuild what it changed.
    pub fn forget(&mut self) {
        self.pose = None;
        self.cache = None;
    }

    /// Brings the lights to `pose` and the integrator `desc` to them,
    /// building it if the cached one is of another description or seed.
    pub fn prepare(&mut self, desc: IntegratorDesc, pose: Pose) -> Result<(), IntegratorError> {
        let seed = self.scene.settings().seed;
        if !matches!(&self.cache, Some(c) if c.desc == desc && c.seed == seed) {
            self.cache = None;
            // As `airlight render --frames` does: built for the file's
            // lights, then moved to the frame.
            self.move_lights(None);
            let integrator = desc.build(&self.scene)?;
            self.cache = Some(Cached { desc, seed, integrator, pose: Some(None) });
        }
        self.move_lights(pose);
        let Some(cached) = self.cache.as_mut() else { unreachable!("built above") };
        if cached.pose != Some(pose) {
            cached.pose = None;
            cached.integrator.lights_changed(&self.scene)?;
            cached.pose = Some(pose);
        }
        Ok(())
    }

    fn move_lights(&mut self, pose: Pose) {
        if self.pose == Some(pose) {
            return;
        }
        self.pose = None;
        // From the file's lights each time, so that a frame's lights do not
        // depend on the frames rendered before it.
        self.scene.set_lights(&self.base_lights);
        if let Some(t) = pose {
            self.scene.at_time(t);
        }
        self.pose = Some(pose);
    }

    /// The integrator [`Shared::prepare`] made ready.
    pub fn integrator(&self) -> &dyn Integrator {
        match &self.cache {
            Some(c) => c.integrator.as_ref(),
            None => unreachable!("prepare() builds the integrator before a render"),
        }
    }
}

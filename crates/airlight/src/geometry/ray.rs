use glam::Vec3;

/// A ray `origin + t·dir`. Camera, shadow and march rays keep `dir` unit length,
/// so `t` is a distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self { origin, dir }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// Moves a surface point off its surface, to the side that `toward` points to,
/// so that a ray leaving it does not hit the surface it starts on. The offset
/// grows with the point's magnitude because f32 spacing does.
#[inline]
pub fn offset_origin(p: Vec3, normal: Vec3, toward: Vec3) -> Vec3 {
    let scale = 1e-4 * (1.0 + p.abs().max_element());
    let side = if normal.dot(toward) >= 0.0 { 1.0 } else { -1.0 };
    p + normal * (side * scale)
}

//! Rays, shapes and the acceleration structure that finds what a ray hits.

mod accel;
mod batch;
mod blocks;
mod box_lanes;
mod bvh;
mod collapse;
mod lanes;
mod one_ray;
mod packet;
mod pages;
mod quad_lanes;
mod ray;
mod records;
pub mod sdf;
mod shape;
mod small;

pub use accel::{Geometry, GeometryBuilder, Hit, SurfaceHit, shadow_rays_traced};
pub use batch::Segment;
pub use collapse::TreeShape;
pub use lanes::LaneWidth;
pub use ray::{Ray, offset_origin};
pub(crate) use records::barycentric as barycentric_coordinates;
pub use sdf::Sdf;
pub(crate) use shape::checksum;
pub use shape::{Shape, intersect_box, intersect_quad, intersect_sphere, intersect_triangle, triangle_blocks};

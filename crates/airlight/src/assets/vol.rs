//! Mitsuba's binary volume format (`.vol`), dense float32, one channel:
//!
//! | bytes  | content                                              |
//! |--------|------------------------------------------------------|
//! | 0–2    | `VOL`                                                |
//! | 3      | version, 3                                           |
//! | 4–7    | encoding, i32: 1 = float32 (the only one read here)  |
//! | 8–19   | resolution x, y, z, i32                              |
//! | 20–23  | channels, i32 (1 here: a density)                    |
//! | 24–47  | box: min x, y, z, max x, y, z, f32                   |
//! | 48–    | values, f32, index ((z·ny + y)·nx + x)·channels + c  |
//!
//! all little-endian. The grid fills the box (medium/grid.rs says where
//! each value sits).

use glam::Vec3;
use std::io::Read;

/// Bytes before the values.
pub const HEADER_BYTES: u64 = 48;

/// Most voxels read (2³² floats are 16 GiB).
pub const MAX_VOXELS: u64 = 1 << 32;

/// A dense one-channel grid as stored: resolution, box, values (x fastest).
#[derive(Clone, Debug, PartialEq)]
pub struct VolGrid {
    pub resolution: [usize; 3],
    pub min: Vec3,
    pub max: Vec3,
    pub values: Vec<f32>,
}

/// The header's resolution and box, checked.
fn header(bytes: &[u8; HEADER_BYTES as usize]) -> Result<([usize; 3], Vec3, Vec3), String> {
    if &bytes[0..3] != b"VOL" {
        return Err(format!(
            "not a Mitsuba volume: it starts with {:?}, not `VOL`",
            String::from_utf8_lossy(&bytes[0..3])
        ));
    }
    if bytes[3] != 3 {
        return Err(format!("volume format version {}; only version 3 is read", bytes[3]));
    }
    let int = |at: usize| i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    let float = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
    match int(4) {
        1 => {}
        2 => return Err("float16 volumes (encoding 2) are not read; store float32 (encoding 1)".into()),
        3 => return Err("8-bit volumes (encoding 3) are not read; store float32 (encoding 1)".into()),
        e => return Err(format!("unknown volume encoding {e}; expected 1 (float32)")),
    }
    let (nx, ny, nz, channels) = (int(8), int(12), int(16), int(20));
    if channels != 1 {
        return Err(format!("the volume has {channels} channels; a density grid has 1"));
    }
    if nx < 1 || ny < 1 || nz < 1 {
        return Err(format!("resolution {nx}×{ny}×{nz}: every side must be at least 1"));
    }
    let voxels = nx as u64 * ny as u64 * nz as u64;
    if voxels > MAX_VOXELS {
        return Err(format!("resolution {nx}×{ny}×{nz} is {voxels} voxels, more than the {MAX_VOXELS} read"));
    }
    let min = Vec3::new(float(24), float(28), float(32));
    let max = Vec3::new(float(36), float(40), float(44));
    if !(min.is_finite() && max.is_finite() && max.cmpgt(min).all()) {
        return Err(format!("its box runs from {min} to {max}; it must be finite with max > min on every axis"));
    }
    Ok(([nx as usize, ny as usize, nz as usize], min, max))
}

/// Reads a `.vol` stream of `length` bytes in all. Refuses a wrong
/// magic, version, encoding or channel count, a size that is absurd or that
/// the memory limit cannot hold (before allocating it), a stream shorter or
/// longer than its header says, and NaN, infinite or negative values (naming
/// the voxel).
pub fn read(mut input: impl Read, length: u64) -> Result<VolGrid, String> {
    let mut head = [0u8; HEADER_BYTES as usize];
    if length < HEADER_BYTES {
        return Err(format!("it holds {length} bytes, fewer than a volume header's {HEADER_BYTES}"));
    }
    input.read_exact(&mut head).map_err(|e| format!("cannot read its header: {e}"))?;
    let (resolution, min, max) = header(&head)?;
    let voxels = resolution.iter().product::<usize>();
    let expected = HEADER_BYTES + 4 * voxels as u64;
    if length != expected {
        let [nx, ny, nz] = resolution;
        let what = if length < expected { "truncated" } else { "longer than its header says" };
        return Err(format!("{what}: {length} bytes, where a {nx}×{ny}×{nz} float32 grid takes {expected}"));
    }
    let mut values = crate::memory::try_vec("the density grid", voxels, 0.0f32).map_err(|e| e.to_string())?;
    let mut chunk = vec![0u8; 1 << 20];
    let mut filled = 0;
    while filled < voxels {
        let n = (voxels - filled).min(chunk.len() / 4);
        input.read_exact(&mut chunk[..4 * n]).map_err(|e| format!("cannot read its values: {e}"))?;
        for (i, v) in chunk[..4 * n].chunks_exact(4).enumerate() {
            values[filled + i] = f32::from_le_bytes(v.try_into().unwrap());
        }
        filled += n;
    }
    if let Some(bad) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
        let [nx, ny, _] = resolution;
        let (x, y, z) = (bad % nx, bad / nx % ny, bad / (nx * ny));
        return Err(format!("voxel ({x}, {y}, {z}) holds {}; densities must be finite and not negative", values[bad]));
    }
    Ok(VolGrid { resolution, min, max, values })
}

/// The `.vol` bytes of a one-channel float32 grid (for tests and tools).
pub fn write(grid: &VolGrid) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_BYTES as usize + 4 * grid.values.len());
    out.extend_from_slice(b"VOL");
    out.push(3);
    out.extend_from_slice(&1i32.to_le_bytes());
    for n in grid.resolution {
        out.extend_from_slice(&(n as i32).to_le_bytes());
    }
    out.extend_from_slice(&1i32.to_le_bytes());
    for v in [grid.min, grid.max] {
        for c in v.to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for v in &grid.values {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> VolGrid {
        VolGrid {
            resolution: [2, 3, 1],
            min: Vec3::new(-1.0, 0.0, 2.0),
            max: Vec3::new(1.0, 3.0, 2.5),
            values: (0..6).map(|i| i as f32 * 0.5).collect(),
        }
    }

    fn read_bytes(bytes: &[u8]) -> Result<VolGrid, String> {
        read(bytes, bytes.len() as u64)
    }

    #[test]
    fn a_written_grid_reads_back_with_x_fastest() {
        let bytes = write(&sample());
        assert_eq!(bytes.len(), 48 + 24);
        // Voxel (1, 2, 0) is value 5 by the index ((0·3 + 2)·2 + 1).
        assert_eq!(f32::from_le_bytes(bytes[48 + 4 * 5..48 + 4 * 6].try_into().unwrap()), 2.5);
        assert_eq!(read_bytes(&bytes).unwrap(), sample());
    }

    #[test]
    fn bad_files_say_what_is_wrong() {
        let good = write(&sample());
        let e = |bytes: &[u8]| read_bytes(bytes).unwrap_err();
        assert!(
            e(&good[..60]).starts_with("truncated: 60 bytes, where a 2×3×1 float32 grid takes 72"),
            "{}",
            e(&good[..60])
        );
        assert!(e(&good[..10]).contains("fewer than a volume header"));
        assert!(e(&[good.clone(), vec![0; 4]].concat()).starts_with("longer than its header says"));
        let mut magic = good.clone();
        magic[0] = b'X';
        assert!(e(&magic).contains("not a Mitsuba volume"));
        let patched = |at: usize, v: i32| {
            let mut b = good.clone();
            b[at..at + 4].copy_from_slice(&v.to_le_bytes());
            b
        };
        assert!(e(&patched(4, 2)).contains("float16"));
        assert!(e(&patched(20, 3)).contains("3 channels"));
        assert!(e(&patched(8, 0)).contains("at least 1"));
        assert!(e(&patched(8, -5)).contains("at least 1"));
        let huge = [patched(8, 1 << 30), vec![]].concat();
        let mut huge = huge;
        huge[12..16].copy_from_slice(&(1i32 << 30).to_le_bytes());
        assert!(e(&huge).contains("more than the"), "{}", e(&huge));
        let mut bbox = good.clone();
        bbox[36..40].copy_from_slice(&(-2.0f32).to_le_bytes());
        assert!(e(&bbox).contains("max > min"));
        for (bad, shown) in [(f32::NAN, "NaN"), (-0.5, "-0.5"), (f32::INFINITY, "inf")] {
            let mut b = good.clone();
            b[48 + 4 * 3..48 + 4 * 4].copy_from_slice(&bad.to_le_bytes());
            let m = e(&b);
            assert!(m.starts_with(&format!("voxel (1, 1, 0) holds {shown}")), "{m}");
        }
    }
}

//! Wavefront OBJ meshes: the vertex positions (`v`) and faces (`f`) a
//! mesh object needs, polygons cut into fans of triangles (the first vertex
//! with each following pair), and the names of the material libraries
//! (`mtllib`) and materials (`usemtl`) the faces use; the libraries are
//! opened by the caller, only when the scene asks for them (mtl.rs).
//! Texture coordinates (`vt`) are read with the faces' `v/vt` pairs, v
//! flipped to Airlight's top-down convention (see [`crate::texture`]).
//! Everything else (normals, groups) is skipped.
//!
//! Indices count from 1, or back from the latest vertex when negative, and
//! may refer to vertices defined later in the file. Errors name the line.
//! The file is counted before it is read, so that the memory a mesh needs
//! is known (and refused when too much) before it is allocated.

use glam::{Vec2, Vec3};

/// Bytes a triangle costs once built (its indices, its share of the BVH and
/// of the vertices), for the up-front memory estimate.
pub const BYTES_PER_TRIANGLE: u64 = 96;

/// A mesh as read: positions, and triangles indexing them.
#[derive(Debug, Default, PartialEq)]
pub struct Obj {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    /// `mtllib` file names, with the line that names them.
    pub libraries: Vec<(String, usize)>,
    /// Runs of triangles that share a `usemtl`: the first triangle of each
    /// run and the material's name with its line (None before any
    /// `usemtl`); a run lasts until the next one starts.
    pub material_runs: Vec<(usize, Option<(String, usize)>)>,
    /// `vt` coordinates as (u, 1 − v).
    pub texcoords: Vec<Vec2>,
    /// For each triangle, the `vt` of its corners; empty unless every face
    /// gives one for every vertex.
    pub triangle_texcoords: Vec<[u32; 3]>,
}

/// What is wrong, and on which line (1-based; 0 for the file as a whole).
#[derive(Debug, PartialEq)]
pub struct ObjError {
    pub line: usize,
    pub message: String,
}

fn fail<T>(line: usize, message: impl Into<String>) -> Result<T, ObjError> {
    Err(ObjError { line, message: message.into() })
}

/// Lines, split on `\n` (a `\r` before it is whitespace), numbered from 1.
fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    bytes.split(|&b| b == b'\n').enumerate().map(|(i, l)| (i + 1, l))
}

fn statement(line: &[u8]) -> (&[u8], impl Iterator<Item = &[u8]>) {
    let mut words = line.split(|b| b.is_ascii_whitespace()).filter(|w| !w.is_empty());
    (words.next().unwrap_or_default(), words)
}

/// Vertices and triangles in `bytes`, counted without reading numbers.
pub fn count(bytes: &[u8]) -> (u64, u64) {
    let (mut vertices, mut triangles) = (0u64, 0u64);
    for (_, line) in lines(bytes) {
        match statement(line) {
            (b"v", _) => vertices += 1,
            (b"f", words) => triangles += (words.count() as u64).saturating_sub(2),
            _ => {}
        }
    }
    (vertices, triangles)
}

/// Reads `bytes` with room for `vertices` and `triangles` (from [`count`]).
pub fn parse(bytes: &[u8], vertices: u64, triangles: u64) -> Result<Obj, ObjError> {
    let mut obj = Obj::default();
    let refused = |count: u64, what: &str, size: u64| ObjError {
        line: 0,
        message: format!(
            "{count} {what} need {}, which could not be allocated",
            crate::memory::format_bytes(count.saturating_mul(size))
        ),
    };
    obj.positions.try_reserve_exact(vertices as usize).map_err(|_| refused(vertices, "vertices", 12))?;
    obj.triangles.try_reserve_exact(triangles as usize).map_err(|_| refused(triangles, "triangles", 12))?;
    // The largest index met, and where: checked once every vertex is known.
    let mut highest: Option<(u32, usize)> = None;
    let mut highest_texcoord: Option<(u32, usize)> = None;
    let mut every_face_textured = true;
    let mut face: Vec<u32> = Vec::new();
    let mut face_texcoords: Vec<u32> = Vec::new();
    for (n, line) in lines(bytes) {
        let (keyword, mut words) = statement(line);
        match keyword {
            b"v" => {
                let mut xyz = [0.0f32; 3];
                for x in &mut xyz {
                    let Some(word) = words.next() else {
                        return fail(n, "a vertex needs three numbers: v x y z");
                    };
                    *x = number(word).ok_or_else(|| ObjError {
                        line: n,
                        message: format!("`{}` is not a number", String::from_utf8_lossy(word)),
                    })?;
                }
                let p = Vec3::from_array(xyz);
                if !p.is_finite() {
                    return fail(n, format!("vertex {} is not finite: {p}", obj.positions.len() + 1));
                }
                if obj.positions.len() >= u32::MAX as usize {
                    return fail(n, format!("more than {} vertices", u32::MAX));
                }
                obj.positions.push(p);
            }
            b"vt" => {
                let mut uv = [0.0f32; 2];
                for (k, x) in uv.iter_mut().enumerate() {
                    // v may be left out (1-D textures): 0.
                    let Some(word) = words.next() else {
                        if k == 1 {
                            break;
                        }
                        return fail(n, "texture coordinates need a number: vt u [v]");
                    };
                    *x = number(word).filter(|x| x.is_finite()).ok_or_else(|| ObjError {
                        line: n,
                        message: format!("`{}` is not a finite number", String::from_utf8_lossy(word)),
                    })?;
                }
                obj.texcoords.push(Vec2::new(uv[0], 1.0 - uv[1]));
            }
            b"f" => {
                face.clear();
                face_texcoords.clear();
                for word in words {
                    let index =
                        vertex_index(word, obj.positions.len()).map_err(|m| ObjError { line: n, message: m })?;
                    if highest.is_none_or(|(h, _)| index > h) {
                        highest = Some((index, n));
                    }
                    face.push(index);
                    match texcoord_index(word, obj.texcoords.len()).map_err(|m| ObjError { line: n, message: m })? {
                        Some(t) => {
                            if highest_texcoord.is_none_or(|(h, _)| t > h) {
                                highest_texcoord = Some((t, n));
                            }
                            face_texcoords.push(t);
                        }
                        None => every_face_textured = false,
                    }
                }
                if face.len() < 3 {
                    return fail(n, format!("a face needs at least 3 vertices, got {}", face.len()));
                }
                if obj.material_runs.is_empty() {
                    obj.material_runs.push((0, None));
                }
                for pair in face[1..].windows(2) {
                    obj.triangles.push([face[0], pair[0], pair[1]]);
                }
                if every_face_textured {
                    for pair in face_texcoords[1..].windows(2) {
                        obj.triangle_texcoords.push([face_texcoords[0], pair[0], pair[1]]);
                    }
                }
            }
            b"usemtl" => {
                let name = words.map(|w| String::from_utf8_lossy(w)).collect::<Vec<_>>().join(" ");
                let run = (obj.triangles.len(), Some((name, n)));
                match obj.material_runs.last_mut() {
                    // A run without faces gives way to the next.
                    Some(last) if last.0 == obj.triangles.len() => *last = run,
                    _ => obj.material_runs.push(run),
                }
            }
            b"mtllib" => {
                for word in words {
                    obj.libraries.push((String::from_utf8_lossy(word).into_owned(), n));
                }
            }
            _ => {}
        }
    }
    if let Some((index, line)) = highest
        && index as usize >= obj.positions.len()
    {
        return fail(
            line,
            format!("a face refers to vertex {}, but the file has {}", index as u64 + 1, obj.positions.len()),
        );
    }
    if obj.triangles.is_empty() {
        return fail(0, "it holds no faces");
    }
    if !every_face_textured {
        obj.triangle_texcoords = Vec::new();
    } else if let Some((index, line)) = highest_texcoord
        && index as usize >= obj.texcoords.len()
    {
        return fail(
            line,
            format!(
                "a face refers to texture coordinates {}, but the file has {}",
                index as u64 + 1,
                obj.texcoords.len()
            ),
        );
    }
    Ok(obj)
}

fn number(word: &[u8]) -> Option<f32> {
    std::str::from_utf8(word).ok()?.parse().ok()
}

/// The 0-based vertex of a face word (`7`, `7/1`, `7//3`, `-2/…`), given
/// the vertices read so far.
fn vertex_index(word: &[u8], defined: usize) -> Result<u32, String> {
    let first = word.split(|&b| b == b'/').next().unwrap_or_default();
    let text = String::from_utf8_lossy(first);
    let i: i64 = text.parse().map_err(|_| format!("`{}` is not a vertex index", String::from_utf8_lossy(word)))?;
    let index = match i {
        0 => return Err("vertex index 0: OBJ counts vertices from 1".into()),
        i if i > 0 => i - 1,
        i => defined as i64 + i,
    };
    if index < 0 {
        return Err(format!("vertex index {i} reaches back before the first vertex ({defined} defined so far)"));
    }
    u32::try_from(index).map_err(|_| format!("vertex index {i} is beyond the {} vertices a mesh may have", u32::MAX))
}

/// The 0-based `vt` of a face word (`7/2`, `7/2/3`, `7/-1`), None when it
/// gives none (`7`, `7//3`).
fn texcoord_index(word: &[u8], defined: usize) -> Result<Option<u32>, String> {
    let Some(second) = word.split(|&b| b == b'/').nth(1).filter(|w| !w.is_empty()) else {
        return Ok(None);
    };
    let text = String::from_utf8_lossy(second);
    let i: i64 = text
        .parse()
        .map_err(|_| format!("`{}`: `{text}` is not a texture coordinate index", String::from_utf8_lossy(word)))?;
    let index = match i {
        0 => return Err("texture coordinate index 0: OBJ counts from 1".into()),
        i if i > 0 => i - 1,
        i => defined as i64 + i,
    };
    if index < 0 {
        return Err(format!("texture coordinate index {i} reaches back before the first ({defined} defined so far)"));
    }
    u32::try_from(index).map(Some).map_err(|_| format!("texture coordinate index {i} is too large"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Obj, ObjError> {
        let (v, t) = count(text.as_bytes());
        parse(text.as_bytes(), v, t)
    }

    #[test]
    fn polygons_become_fans_and_indices_may_be_relative() {
        let obj =
            read("# quad\nmtllib evil.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 1.0\nvt 0 0\ng g\nf 1/1 2//1 3 -1\n")
                .unwrap();
        assert_eq!(obj.positions.len(), 4);
        assert_eq!(obj.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(obj.libraries, vec![("evil.mtl".to_string(), 2)]);
        assert_eq!(obj.material_runs, vec![(0, None)]);
        // Not every vertex gives a `vt`: no texture coordinates.
        assert!(obj.triangle_texcoords.is_empty());
        assert_eq!(count(b"v 0 0 0\r\nf 1 1 1 1 1\n"), (1, 3));
        // A forward reference is allowed; \r\n line ends too.
        assert_eq!(read("f 1 2 3\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\n").unwrap().triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn texture_coordinates_follow_the_faces_with_v_flipped() {
        let obj =
            read("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0.25\nf 1/1 2/2 3/3 4/-1\n").unwrap();
        assert_eq!(
            obj.texcoords,
            vec![Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.25, 1.0)]
        );
        assert_eq!(obj.triangle_texcoords, vec![[0, 1, 2], [0, 2, 3]]);
        let e = read("v 0 0 0\nvt 0 0\nf 1/1 1/2 1/1\n").unwrap_err();
        assert_eq!(
            e,
            ObjError { line: 3, message: "a face refers to texture coordinates 2, but the file has 1".into() }
        );
        let e = read("v 0 0 0\nvt 0 nan\n").unwrap_err();
        assert_eq!(e, ObjError { line: 2, message: "`nan` is not a finite number".into() });
    }

    #[test]
    fn faces_keep_the_material_they_were_given() {
        let obj =
            read("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nusemtl a\nusemtl warm light\nf 1 2 3 3\nusemtl a\nf 3 2 1\n")
                .unwrap();
        let runs: Vec<(usize, Option<&str>)> =
            obj.material_runs.iter().map(|(start, m)| (*start, m.as_ref().map(|(n, _)| n.as_str()))).collect();
        assert_eq!(runs, vec![(0, None), (1, Some("warm light")), (3, Some("a"))]);
        assert_eq!(obj.material_runs[1].1.as_ref().unwrap().1, 6, "the line of its usemtl");
    }

    #[test]
    fn errors_name_the_line() {
        let cases = [
            ("v 0 0\n", 1, "a vertex needs three numbers: v x y z"),
            ("v 0 0 x\n", 1, "`x` is not a number"),
            ("\nv 0 0 inf\n", 2, "vertex 1 is not finite: [0, 0, inf]"),
            ("v 0 0 0\nf 1 1\n", 2, "a face needs at least 3 vertices, got 2"),
            ("v 0 0 0\nf 0 1 1\n", 2, "vertex index 0: OBJ counts vertices from 1"),
            ("v 0 0 0\nf -2 1 1\n", 2, "vertex index -2 reaches back before the first vertex (1 defined so far)"),
            ("v 0 0 0\nf 1 1 9\nf 1 1 1\n", 2, "a face refers to vertex 9, but the file has 1"),
            (
                "v 0 0 0\nf 1 1 99999999999\n",
                2,
                "vertex index 99999999999 is beyond the 4294967295 vertices a mesh may have",
            ),
            ("v 0 0 0\nf 1 1 x\n", 2, "`x` is not a vertex index"),
            ("v 0 0 0\n", 0, "it holds no faces"),
        ];
        for (text, line, message) in cases {
            assert_eq!(read(text), Err(ObjError { line, message: message.into() }), "{text:?}");
        }
    }
}

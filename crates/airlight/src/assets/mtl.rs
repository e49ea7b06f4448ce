//! Wavefront MTL material libraries, as far as Airlight's materials go: a
//! material (`newmtl NAME`) gives its diffuse colour `Kd` (the albedo) and
//! its emitted colour `Ke` (radiance, W/(m²·sr)); everything else (`Ka`,
//! `Ks`, `Ns`, `d`, `illum`, other texture maps) is skipped. A `map_Kd`
//! names a diffuse texture (its options, such as `-bm 1`, are skipped; the
//! file name is the last word), which the caller reads.

use super::obj::ObjError;
use glam::Vec3;

/// One `newmtl` block.
#[derive(Clone, Debug, PartialEq)]
pub struct MtlMaterial {
    pub name: String,
    /// The line of its `newmtl`.
    pub line: usize,
    pub diffuse: Option<Vec3>,
    pub emission: Option<Vec3>,
    /// The `map_Kd` texture it names, with the line that names it.
    pub diffuse_map: Option<(String, usize)>,
}

/// The materials of a library, in file order.
pub fn parse(text: &str) -> Result<Vec<MtlMaterial>, ObjError> {
    let mut materials: Vec<MtlMaterial> = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let n = index + 1;
        let mut words = line.split_ascii_whitespace();
        let Some(keyword) = words.next() else { continue };
        if keyword == "newmtl" {
            let name = words.collect::<Vec<_>>().join(" ");
            if name.is_empty() {
                return Err(ObjError { line: n, message: "newmtl needs a name".into() });
            }
            materials.push(MtlMaterial { name, line: n, diffuse: None, emission: None, diffuse_map: None });
            continue;
        }
        if !matches!(keyword, "Kd" | "Ke" | "map_Kd") {
            continue;
        }
        let Some(material) = materials.last_mut() else {
            return Err(ObjError { line: n, message: format!("{keyword} before any newmtl") });
        };
        match keyword {
            "map_Kd" => {
                let file =
                    words.last().ok_or_else(|| ObjError { line: n, message: "map_Kd needs a file name".into() })?;
                material.diffuse_map = Some((file.to_string(), n));
            }
            _ => {
                let colour = colour(keyword, words).map_err(|message| ObjError { line: n, message })?;
                if keyword == "Kd" {
                    material.diffuse = Some(colour);
                } else {
                    material.emission = Some(colour);
                }
            }
        }
    }
    Ok(materials)
}

/// `r g b`, or one value for all three; finite and ≥ 0.
fn colour<'a>(keyword: &str, words: impl Iterator<Item = &'a str>) -> Result<Vec3, String> {
    let words: Vec<&str> = words.collect();
    if words.first() == Some(&"spectral") || words.first() == Some(&"xyz") {
        return Err(format!("{keyword} {}: only r g b colours are read", words[0]));
    }
    let values = words
        .iter()
        .map(|w| w.parse::<f32>().map_err(|_| format!("{keyword}: `{w}` is not a number")))
        .collect::<Result<Vec<f32>, String>>()?;
    let colour = match values[..] {
        [v] => Vec3::splat(v),
        [r, g, b] => Vec3::new(r, g, b),
        _ => return Err(format!("{keyword} needs three numbers (r g b), got {}", values.len())),
    };
    if !(colour.is_finite() && colour.min_element() >= 0.0) {
        return Err(format!("{keyword} must be finite and ≥ 0, got {colour}"));
    }
    Ok(colour)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_diffuse_and_emitted_colours() {
        let text = "# lib\nnewmtl wall\nKa 1 1 1\nKd 0.5 0.25 0.125\nillum 2\n\nnewmtl lamp shade\nKe 10\nKd 0\nmap_Kd -bm 1 tex/lamp.png\n";
        let m = parse(text).unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!((m[0].name.as_str(), m[0].line), ("wall", 2));
        assert_eq!(m[0].diffuse, Some(Vec3::new(0.5, 0.25, 0.125)));
        assert_eq!(m[0].emission, None);
        assert_eq!(m[1].name, "lamp shade");
        assert_eq!(m[1].emission, Some(Vec3::splat(10.0)));
        assert_eq!(m[1].diffuse, Some(Vec3::ZERO));
        assert_eq!(m[1].diffuse_map, Some(("tex/lamp.png".to_string(), 10)));
    }

    #[test]
    fn errors_name_the_line() {
        let cases = [
            ("Kd 1 1 1\n", 1, "Kd before any newmtl"),
            ("newmtl\n", 1, "newmtl needs a name"),
            ("newmtl a\nKd 1 x 1\n", 2, "Kd: `x` is not a number"),
            ("newmtl a\n\nKe 1 1\n", 3, "Ke needs three numbers (r g b), got 2"),
            ("newmtl a\nKd -1 0 0\n", 2, "Kd must be finite and ≥ 0, got [-1, 0, 0]"),
            ("newmtl a\nKd spectral x.spd\n", 2, "Kd spectral: only r g b colours are read"),
            ("newmtl a\nmap_Kd\n", 2, "map_Kd needs a file name"),
        ];
        for (text, line, message) in cases {
            assert_eq!(parse(text), Err(ObjError { line, message: message.into() }), "{text:?}");
        }
    }
}

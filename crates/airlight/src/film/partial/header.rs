//! A partial file's header: its fields as `key=value` lines of text in
//! one attribute, and back, with what is wrong with a field said in words.

use super::{FIELDS_ATTRIBUTE, PARTIAL_FORMAT, PARTIAL_FORMAT_1, PartialHeader};
use std::collections::BTreeMap;
use std::ops::Range;

/// The header's fields as the text of the [`FIELDS_ATTRIBUTE`]: a
/// `key=value` line each.
pub(super) fn header_text(header: &PartialHeader) -> String {
    header_fields(header).iter().map(|(key, value)| format!("{key}={value}\n")).collect()
}

/// The header's fields as (key, value) text, in a fixed order, the format
/// tag first.
pub(super) fn header_fields(h: &PartialHeader) -> Vec<(&'static str, String)> {
    vec![
        ("format", PARTIAL_FORMAT.to_string()),
        ("version", h.version.clone()),
        ("scene", h.scene.clone()),
        ("seed", h.seed.to_string()),
        ("width", h.width.to_string()),
        ("height", h.height.to_string()),
        ("spp", h.spp.to_string()),
        ("samples", format!("{}..{}", h.samples.start, h.samples.end)),
        ("rows", format!("{}..{}", h.rows.start, h.rows.end)),
        ("frame", h.frame.map_or("-".into(), |(k, n)| format!("{k}/{n}"))),
        // Shortest text that reads back as the same f32.
        ("exposure", format!("{:?}", h.exposure)),
        ("tonemap", h.tonemap.name().to_string()),
    ]
}

/// The fields of a header's text attributes: the lines of
/// [`FIELDS_ATTRIBUTE`], or else (the first format) the attributes named
/// `airlight.<key>`.
fn read_fields(
    attributes: &std::collections::HashMap<exr::meta::attribute::Text, exr::meta::attribute::AttributeValue>,
) -> Result<BTreeMap<String, String>, String> {
    use exr::meta::attribute::AttributeValue;
    let texts = attributes.iter().filter_map(|(key, value)| match value {
        AttributeValue::Text(text) => Some((key.to_string(), text.to_string())),
        _ => None,
    });
    let mut fields = BTreeMap::new();
    let mut packed = None;
    for (key, value) in texts {
        if key == FIELDS_ATTRIBUTE {
            packed = Some(value);
        } else if let Some(field) = key.strip_prefix("airlight.") {
            fields.insert(field.to_string(), value);
        }
    }
    if let Some(lines) = packed {
        fields.clear();
        for line in lines.lines() {
            let (key, value) = line
                .split_once('=')
                .ok_or_else(|| format!("its header's `{FIELDS_ATTRIBUTE}` has a line without `=`: `{line}`"))?;
            fields.insert(key.to_string(), value.to_string());
        }
    }
    Ok(fields)
}

/// The text of field `key` of a partial file's header, if it has one.
pub(super) fn field(
    attributes: &std::collections::HashMap<exr::meta::attribute::Text, exr::meta::attribute::AttributeValue>,
    key: &str,
) -> Result<Option<String>, String> {
    Ok(read_fields(attributes)?.remove(key))
}

/// The header that a partial file's attributes describe, checked: every
/// field present and in range, the format one this build reads.
pub(super) fn parse_header(
    attributes: &std::collections::HashMap<exr::meta::attribute::Text, exr::meta::attribute::AttributeValue>,
) -> Result<PartialHeader, String> {
    let fields = read_fields(attributes)?;
    let get = |key: &str| -> Result<String, String> {
        fields.get(key).cloned().ok_or_else(|| format!("not an Airlight partial render (no `{key}` in its header)"))
    };
    let format = get("format")?;
    if format != PARTIAL_FORMAT && format != PARTIAL_FORMAT_1 {
        return Err(format!(
            "a partial render of format `{format}`; this Airlight reads `{PARTIAL_FORMAT}` and `{PARTIAL_FORMAT_1}`"
        ));
    }
    let number = |key: &str| -> Result<u64, String> {
        get(key)?.parse().map_err(|_| format!("its header's `{key}` is not a whole number"))
    };
    let range = |key: &str| -> Result<Range<u64>, String> {
        let text = get(key)?;
        let (a, b) = text.split_once("..").ok_or_else(|| format!("its header's `{key}` is not a range a..b"))?;
        let parse = |s: &str| s.parse::<u64>().map_err(|_| format!("its header's `{key}` is not a range a..b"));
        let (a, b) = (parse(a)?, parse(b)?);
        if a > b {
            return Err(format!("its header's `{key}` runs backwards: {a}..{b}"));
        }
        Ok(a..b)
    };
    let small = |v: u64, key: &str| u32::try_from(v).map_err(|_| format!("its header's `{key}` is too large: {v}"));
    let (width, height) = (small(number("width")?, "width")?, small(number("height")?, "height")?);
    let spp = small(number("spp")?, "spp")?;
    let samples = range("samples")?;
    let rows = range("rows")?;
    if samples.end > spp as u64 || rows.end > height as u64 {
        return Err(format!(
            "its header's samples {samples:?} or rows {rows:?} lie outside the image's {spp} spp or {height} rows"
        ));
    }
    if width as u64 * (rows.end - rows.start) > crate::film::MAX_PIXELS {
        return Err(format!(
            "its header declares {width}×{} pixels, more than Airlight renders",
            rows.end - rows.start
        ));
    }
    let frame = match get("frame")?.as_str() {
        "-" => None,
        text => {
            let bad = || format!("its header's frame `{text}` is not k/n with 0 ≤ k < n");
            let (k, n) = text.split_once('/').ok_or_else(bad)?;
            let (k, n): (u32, u32) = (k.parse().map_err(|_| bad())?, n.parse().map_err(|_| bad())?);
            if k >= n {
                return Err(bad());
            }
            Some((k, n))
        }
    };
    let exposure = get("exposure")?
        .parse::<f32>()
        .ok()
        .filter(|e| e.is_finite())
        .ok_or("its header's `exposure` is not a finite number")?;
    let tonemap = get("tonemap")?.parse().map_err(|e| format!("its header's `tonemap`: {e}"))?;
    Ok(PartialHeader {
        exposure,
        tonemap,
        version: get("version")?,
        scene: get("scene")?,
        seed: number("seed")?,
        width,
        height,
        spp,
        samples,
        rows: rows.start as u32..rows.end as u32,
        frame,
    })
}

//! Partial renders: the exact sums of some samples of some rows of an image,
//! written as an EXR file that `merge` adds up, and `--resume` continues.
//!
//! A partial file holds, for each pixel of its band of rows, the
//! accumulator's fixed-point sums ([`PixelSum`]) losslessly as 32-bit
//! unsigned channels: `S<c>0`..`S<c>3` for the sum of channel c (R, G, B),
//! lowest word first, `Q<c>0`..`Q<c>3` for the sum of squares, and `N0`,
//! `N1` for the sample count. One text attribute of the header,
//! `airlight.partial`, says in `key=value` lines what the sums are of
//! ([`PartialHeader`]): the Airlight version, a fingerprint of the resolved
//! scene, the seed, the image size, the total spp, the sample range, the
//! band of rows and the frame. One attribute, not one per field: the EXR
//! writer orders a header's attributes as its hash map iterates, which
//! differs from process to process, and a file's bytes should not.
//! Files of the first format (`airlight-partial-1`), with an attribute per
//! field, are still read. Since each sample's random
//! stream is keyed by (seed, pixel, sample number) and the sums are exact
//! integers, parts that together hold every sample of every pixel once add
//! up to the very sums one render makes: the merged image is the same, bit
//! for bit.

mod header;
mod merge;

pub use merge::{merge, piece};

use super::{Accumulator, PixelSum};
use header::{header_text, parse_header};
use std::io::{self, Write};
use std::ops::Range;
use std::path::Path;

/// The format tag written in every partial file.
pub const PARTIAL_FORMAT: &str = "airlight-partial-2";

/// The first format: the same fields, each in an attribute of its own
/// named `airlight.<key>`. Read, no longer written.
const PARTIAL_FORMAT_1: &str = "airlight-partial-1";

/// The header attribute that holds a partial's fields.
const FIELDS_ATTRIBUTE: &str = "airlight.partial";

/// What a partial file's sums are of.
#[derive(Clone, Debug, PartialEq)]
pub struct PartialHeader {
    /// The Airlight version that rendered it.
    pub version: String,
    /// Fingerprint of the resolved scene and integrator (command-line
    /// overrides applied), as 16 hexadecimal digits.
    pub scene: String,
    pub seed: u64,
    pub width: u32,
    pub height: u32,
    /// Samples per pixel of the whole render.
    pub spp: u32,
    /// The sample numbers held, within 0..spp.
    pub samples: Range<u64>,
    /// The rows held, within 0..height.
    pub rows: Range<u32>,
    /// Frame k of n of an animation, if it is one.
    pub frame: Option<(u32, u32)>,
    /// How a PNG of the merged image is made: the scene's exposure (stops)
    /// and tone curve.
    pub exposure: f32,
    pub tonemap: super::Tonemap,
}

/// A partial render: its header and its sums.
#[derive(Clone, Debug, PartialEq)]
pub struct Partial {
    pub header: PartialHeader,
    pub sums: Accumulator,
}

const CHANNELS: [char; 3] = ['R', 'G', 'B'];

impl Partial {
    /// Encodes the partial as EXR bytes: see [`encode`].
    pub fn encode(&self) -> io::Result<Vec<u8>> {
        encode(&self.header, &self.sums)
    }

    /// Writes the partial to `path`, whole or not at all.
    pub fn write(&self, path: &Path) -> io::Result<()> {
        write(path, &self.header, &self.sums)
    }

    /// Reads a partial file; the error says what is wrong with it (not an
    /// EXR, truncated, not a partial, a field missing or out of range).
    pub fn read(path: &Path) -> Result<Partial, String> {
        use exr::prelude::*;
        let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| format!("not a readable EXR: {e}"))?;
        let exr_header = meta.headers.first().ok_or("an EXR without layers")?;
        let attributes = &exr_header.own_attributes.other;
        let header = parse_header(attributes)?;
        let size = header.width as u64 * (header.rows.end - header.rows.start) as u64;
        // The EXR's own size, checked before its pixels are read: a small
        // file may claim a huge image.
        let window = exr_header.layer_size;
        if (window.width() as u64, window.height() as u64)
            != (header.width as u64, (header.rows.end - header.rows.start) as u64)
        {
            return Err(format!(
                "its pixels are {}×{}, its header says {}×{}",
                window.width(),
                window.height(),
                header.width,
                header.rows.end - header.rows.start
            ));
        }
        let channels = exr_header.channels.list.len() as u64;
        crate::memory::check(
            format!("reading a {}×{} partial render", header.width, header.rows.end - header.rows.start),
            size.saturating_mul(channels * 4 + crate::film::ACCUMULATOR_BYTES_PER_PIXEL as u64),
        )
        .map_err(|e| e.to_string())?;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_file(path)
            .map_err(|e| format!("cannot read its pixels (truncated or damaged?): {e}"))?;
        let layer = &image.layer_data;
        if (layer.size.width() as u64, layer.size.height() as u64)
            != (header.width as u64, (header.rows.end - header.rows.start) as u64)
        {
            return Err(format!(
                "its pixels are {}×{}, its header says {}×{}",
                layer.size.width(),
                layer.size.height(),
                header.width,
                header.rows.end - header.rows.start
            ));
        }
        let channel = |name: String| -> std::result::Result<&[u32], String> {
            let found = layer.channel_data.list.iter().find(|c| c.name.to_string() == name);
            match found.map(|c| &c.sample_data) {
                Some(FlatSamples::U32(v)) if v.len() as u64 == size => Ok(v.as_slice()),
                Some(_) => Err(format!("channel {name} is not 32-bit unsigned of the image's size")),
                None => Err(format!("channel {name} is missing")),
            }
        };
        let mut sums = Accumulator::band(header.width, header.height, header.rows.clone());
        let pixels = sums.pixels_mut();
        for (c, name) in CHANNELS.iter().enumerate() {
            for k in 0..4 {
                let (s, q) = (channel(format!("S{name}{k}"))?, channel(format!("Q{name}{k}"))?);
                for (i, p) in pixels.iter_mut().enumerate() {
                    p.sum[c] |= ((s[i] as u128) << (32 * k)) as i128;
                    p.sum_squares[c] |= ((q[i] as u128) << (32 * k)) as i128;
                }
            }
        }
        let (n0, n1) = (channel("N0".into())?, channel("N1".into())?);
        for (i, p) in pixels.iter_mut().enumerate() {
            p.count = n0[i] as u64 | (n1[i] as u64) << 32;
        }
        check_sums(&header, sums.pixels())?;
        if let Some(expected) = header::field(attributes, CHECKSUM_KEY)?
            && expected != checksum(sums.pixels())
        {
            return Err(
                "its sums do not match their checksum: the file was damaged or edited after it was written".into()
            );
        }
        Ok(Partial { header, sums })
    }
}

/// Every pixel of a part holds its header's samples, no more and no fewer,
/// and sums of squares, which are never negative: a file that says
/// otherwise would merge or resume into a wrong image.
fn check_sums(header: &PartialHeader, pixels: &[PixelSum]) -> Result<(), String> {
    let samples = header.samples.end - header.samples.start;
    let width = header.width.max(1) as usize;
    for (i, p) in pixels.iter().enumerate() {
        let at = || format!("pixel (x {}, y {})", i % width, header.rows.start as usize + i / width);
        if p.count != samples {
            return Err(format!(
                "{} holds {} samples, its header says {samples} (samples {:?})",
                at(),
                p.count,
                header.samples
            ));
        }
        if p.sum_squares.iter().any(|&s| s < 0) {
            return Err(format!("{} holds a negative sum of squares, which no render makes", at()));
        }
    }
    Ok(())
}

/// Writes the sums `sums` with their header as a partial file at `path`,
/// whole or not at all, the bytes of [`encode`]. The file is encoded
/// straight to disk, holding neither a copy of the sums nor the encoded
/// file in memory (a running render's checkpoint writes its accumulator so).
pub fn write(path: &Path, header: &PartialHeader, sums: &Accumulator) -> io::Result<()> {
    super::write_atomically_with(path, |file| {
        let mut out = io::BufWriter::new(file);
        encode_into(header, sums, &[(FIELDS_ATTRIBUTE, fields_text(header, sums))], &mut out)?;
        out.flush()
    })
}

/// Encodes sums and their header as a partial file's EXR bytes: ZIP, lines
/// in increasing order and the fields in one attribute, so that the same
/// sums and header give the same bytes whatever the thread count and the
/// run. The channels are read from the sums line by line as the EXR writer
/// compresses them, so that the encoding holds no copy of
/// the sums (104 bytes a pixel).
pub fn encode(header: &PartialHeader, sums: &Accumulator) -> io::Result<Vec<u8>> {
    encode_with_attributes(header, sums, &[(FIELDS_ATTRIBUTE, fields_text(header, sums))])
}

/// The header's fields and the checksum of the sums (`sums=`), as the
/// text of the [`FIELDS_ATTRIBUTE`].
fn fields_text(header: &PartialHeader, sums: &Accumulator) -> String {
    format!("{}{CHECKSUM_KEY}={}\n", header_text(header), checksum(sums.pixels()))
}

/// The key of the sums' checksum among a partial's fields.
const CHECKSUM_KEY: &str = "sums";

/// A checksum of every pixel's sums and count, in order: 16 hexadecimal
/// digits of their 64-bit FNV-1a hash (Fowler, Noll and Vo). A part whose
/// sums were damaged or edited after it was written no longer matches.
fn checksum(pixels: &[PixelSum]) -> String {
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            hash = (hash ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for p in pixels {
        eat(&p.count.to_le_bytes());
        for c in 0..3 {
            eat(&p.sum[c].to_le_bytes());
            eat(&p.sum_squares[c].to_le_bytes());
        }
    }
    format!("{hash:016x}")
}

/// The EXR bytes of the sums with these text attributes in the header.
fn encode_with_attributes(
    header: &PartialHeader,
    sums: &Accumulator,
    text_attributes: &[(&str, String)],
) -> io::Result<Vec<u8>> {
    let mut out = io::Cursor::new(Vec::new());
    encode_into(header, sums, text_attributes, &mut out)?;
    Ok(out.into_inner())
}

/// Encodes the sums with these text attributes in the header into `out`.
fn encode_into(
    header: &PartialHeader,
    sums: &Accumulator,
    text_attributes: &[(&str, String)],
    out: &mut (impl io::Write + io::Seek),
) -> io::Result<()> {
    use exr::prelude::*;
    let (width, rows) = (header.width as usize, (header.rows.end - header.rows.start) as usize);
    let pixels = sums.pixels();
    if pixels.len() != width * rows {
        return Err(io::Error::other("partial sums do not match their header's size"));
    }
    let channel = |name: String, word: Word| AnyChannel::new(name.as_str(), SumWords { pixels, width, word });
    let mut list = Vec::new();
    for (c, name) in CHANNELS.iter().enumerate() {
        for k in 0..4 {
            list.push(channel(format!("S{name}{k}"), Word::Sum { channel: c, k }));
            list.push(channel(format!("Q{name}{k}"), Word::Square { channel: c, k }));
        }
    }
    list.extend((0..2).map(|k| channel(format!("N{k}"), Word::Count { k })));
    let mut attributes = LayerAttributes::named("airlight-partial");
    for (key, value) in text_attributes {
        let text = Text::new_or_none(value).ok_or_else(|| io::Error::other("non-ASCII header"))?;
        attributes.other.insert(Text::new_or_panic(key), AttributeValue::Text(text));
    }
    let encoding =
        Encoding { compression: Compression::ZIP16, blocks: Blocks::ScanLines, line_order: LineOrder::Increasing };
    let layer = Layer::new((width, rows), attributes, encoding, AnyChannels::sort(list.into()));
    exr::prelude::Image::from_layer(layer).write().to_buffered(out).map_err(io::Error::other)
}

/// Which 32-bit word of a pixel's sums a channel of a partial file holds:
/// word `k` (0 the lowest) of the sum or the sum of squares of colour
/// channel `channel`, or of the sample count.
#[derive(Clone, Copy, Debug)]
enum Word {
    Sum { channel: usize, k: u32 },
    Square { channel: usize, k: u32 },
    Count { k: u32 },
}

impl Word {
    fn of(self, p: &PixelSum) -> u32 {
        let word = |v: u128, k: u32| (v >> (32 * k)) as u32;
        match self {
            Word::Sum { channel, k } => word(p.sum[channel] as u128, k),
            Word::Square { channel, k } => word(p.sum_squares[channel] as u128, k),
            Word::Count { k } => word(p.count as u128, k),
        }
    }
}

/// One channel of a partial file, `word` of every pixel of `pixels`
/// (`width` to a row), given to the EXR writer a line at a time as it asks.
#[derive(Clone, Copy, Debug)]
struct SumWords<'a> {
    pixels: &'a [PixelSum],
    width: usize,
    word: Word,
}

impl<'slf, 'a: 'slf> exr::image::write::samples::WritableSamples<'slf> for SumWords<'a> {
    type Writer = SumWords<'a>;

    fn sample_type(&self) -> exr::meta::attribute::SampleType {
        exr::meta::attribute::SampleType::U32
    }

    fn infer_level_modes(&self) -> (exr::meta::attribute::LevelMode, exr::math::RoundingMode) {
        (exr::meta::attribute::LevelMode::Singular, exr::math::RoundingMode::Down)
    }

    fn create_samples_writer(&'slf self, _header: &exr::meta::header::Header) -> SumWords<'a> {
        *self
    }
}

impl exr::image::write::samples::SamplesWriter for SumWords<'_> {
    fn extract_line(&self, line: exr::block::lines::LineRefMut<'_>) {
        let start = line.location.position.y() * self.width + line.location.position.x();
        let pixels = &self.pixels[start..start + line.location.sample_count];
        // The line's buffer is sized by the writer for exactly these
        // samples; writing them into it cannot fail.
        line.write_samples(|i| self.word.of(&pixels[i])).expect("a line's buffer holds its samples");
    }
}

#[cfg(test)]
mod tests {
    use super::header::header_fields;
    use super::*;
    use crate::Rgb;

    /// A partial of a 3×4 image: these rows and samples of made-up sums.
    pub(super) fn part(rows: Range<u32>, samples: Range<u64>, seed: u64) -> Partial {
        let mut sums = Accumulator::band(3, 4, rows.clone());
        let first = rows.start as usize * 3;
        for (i, p) in sums.pixels_mut().iter_mut().enumerate() {
            for s in samples.clone() {
                p.add(Rgb::new((first + i) as f32 + 0.25, s as f32 * 1e-3, -1.5e7));
            }
        }
        let header = PartialHeader {
            version: "0.1.0".into(),
            scene: "0123456789abcdef".into(),
            seed,
            width: 3,
            height: 4,
            spp: 5,
            samples,
            rows,
            frame: Some((1, 3)),
            exposure: -0.5,
            tonemap: crate::film::Tonemap::Filmic,
        };
        Partial { header, sums }
    }

    #[test]
    fn a_partial_file_round_trips_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.exr");
        let p = part(1..3, 2..5, 7);
        p.write(&path).unwrap();
        assert_eq!(Partial::read(&path).unwrap(), p);
        // Encoded straight to the file, the bytes of the encoding in memory.
        assert_eq!(std::fs::read(&path).unwrap(), p.encode().unwrap());
    }

    /// The writer orders a header's attributes as a hash map with keys
    /// drawn per map iterates; the fields' one attribute makes the bytes
    /// the same on every encoding.
    #[test]
    fn a_partial_encodes_to_the_same_bytes_every_time() {
        let p = part(0..4, 0..5, 7);
        let first = p.encode().unwrap();
        for _ in 0..8 {
            assert_eq!(p.encode().unwrap(), first);
        }
    }

    /// A file of the first format, an attribute per field, as earlier
    /// builds wrote them.
    #[test]
    fn a_partial_file_of_the_first_format_reads() {
        let p = part(1..3, 2..5, 7);
        let fields: Vec<(String, String)> = header_fields(&p.header)
            .into_iter()
            .map(|(key, value)| {
                let value = if key == "format" { PARTIAL_FORMAT_1.to_string() } else { value };
                (format!("airlight.{key}"), value)
            })
            .collect();
        let attributes: Vec<(&str, String)> = fields.iter().map(|(k, v)| (k.as_str(), v.clone())).collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p1.exr");
        std::fs::write(&path, encode_with_attributes(&p.header, &p.sums, &attributes).unwrap()).unwrap();
        assert_eq!(Partial::read(&path).unwrap(), p);
        let unknown = [(FIELDS_ATTRIBUTE, "format=airlight-partial-9\n".to_string())];
        std::fs::write(&path, encode_with_attributes(&p.header, &p.sums, &unknown).unwrap()).unwrap();
        let e = Partial::read(&path).unwrap_err();
        assert!(e.contains("of format `airlight-partial-9`"), "{e}");
    }
    /// Sums that disagree with their header (counts of 0, 7 or 2⁶⁴ − 1
    /// where it says 3 samples; a negative sum of squares) or with their
    /// checksum are refused, not merged or resumed into a wrong image.
    #[test]
    fn sums_that_disagree_with_the_header_or_the_checksum_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.exr");
        let refused = |p: &Partial| {
            p.write(&path).unwrap();
            Partial::read(&path).unwrap_err()
        };
        for count in [0, 7, u64::MAX] {
            let mut p = part(1..3, 2..5, 7);
            p.sums.pixels_mut()[4].count = count;
            let e = refused(&p);
            assert!(e.contains(&format!("pixel (x 1, y 2) holds {count} samples, its header says 3")), "{e}");
        }
        let mut p = part(1..3, 2..5, 7);
        p.sums.pixels_mut()[0].sum_squares[1] = -1;
        assert!(refused(&p).contains("negative sum of squares"));
        // A sum changed after the checksum was taken.
        let p = part(1..3, 2..5, 7);
        let mut edited = p.clone();
        edited.sums.pixels_mut()[2].sum[0] += 1;
        let fields = format!("{}{CHECKSUM_KEY}={}\n", header_text(&p.header), checksum(p.sums.pixels()));
        let bytes = encode_with_attributes(&edited.header, &edited.sums, &[(FIELDS_ATTRIBUTE, fields)]).unwrap();
        std::fs::write(&path, bytes).unwrap();
        let e = Partial::read(&path).unwrap_err();
        assert!(e.contains("do not match their checksum"), "{e}");
    }
}

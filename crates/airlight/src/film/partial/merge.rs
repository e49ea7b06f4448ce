//! Adding up partial renders of one image, after checking that they fit
//! together, and cutting a render into pieces to be rendered apart.

use super::{Partial, PartialHeader};
use crate::film::Accumulator;
use std::ops::Range;

/// Adds up partial renders of one image, after checking that they are of
/// the same scene, seed, size, spp and frame, and that together they hold
/// every sample of every pixel exactly once. `parts` pairs each partial
/// with the name it is reported by (its file). The error names what is
/// mismatched, missing or held twice.
pub fn merge(parts: &[(String, Partial)]) -> Result<(PartialHeader, Accumulator), String> {
    let Some((first_name, first)) = parts.first() else {
        return Err("no partial renders to merge".into());
    };
    let a = &first.header;
    for (name, part) in &parts[1..] {
        let b = &part.header;
        let differ = |what: &str, x: &dyn std::fmt::Display, y: &dyn std::fmt::Display| {
            Err(format!("{name} and {first_name} are of different renders: {what} {y} and {x}"))
        };
        if b.seed != a.seed {
            return differ("seed", &a.seed, &b.seed);
        }
        if (b.width, b.height) != (a.width, a.height) {
            return differ("size", &format!("{}×{}", a.width, a.height), &format!("{}×{}", b.width, b.height));
        }
        if b.spp != a.spp {
            return differ("spp", &a.spp, &b.spp);
        }
        if b.frame != a.frame {
            return differ("frame", &format!("{:?}", a.frame), &format!("{:?}", b.frame));
        }
        if b.version != a.version {
            return differ("Airlight version", &a.version, &b.version);
        }
        // Last: the fingerprint covers the fields above too, which are
        // named more plainly on their own.
        if b.scene != a.scene {
            return differ("scene fingerprint", &a.scene, &b.scene);
        }
    }
    check_coverage(parts, a.height, a.spp as u64)?;
    let mut total = Accumulator::new(a.width, a.height);
    for (name, part) in parts {
        total.merge(&part.sums).map_err(|e| format!("{name}: {e}"))?;
    }
    let header = PartialHeader { samples: 0..a.spp as u64, rows: 0..a.height, ..a.clone() };
    Ok((header, total))
}

/// Checks that the parts' rectangles (rows × sample numbers) tile
/// [0, height) × [0, spp) exactly.
fn check_coverage(parts: &[(String, Partial)], height: u32, spp: u64) -> Result<(), String> {
    let mut cuts: Vec<u32> = vec![0, height];
    for (_, p) in parts {
        cuts.extend([p.header.rows.start, p.header.rows.end]);
    }
    cuts.sort_unstable();
    cuts.dedup();
    for band in cuts.windows(2) {
        let (r0, r1) = (band[0], band[1]);
        let mut spans: Vec<(u64, u64, &str)> = parts
            .iter()
            .filter(|(_, p)| p.header.rows.start <= r0 && p.header.rows.end >= r1)
            .filter(|(_, p)| !p.header.samples.is_empty())
            .map(|(name, p)| (p.header.samples.start, p.header.samples.end, name.as_str()))
            .collect();
        spans.sort_unstable();
        let mut next = 0u64;
        let mut last_name = "";
        for (s0, s1, name) in spans {
            if s0 > next {
                return Err(format!("samples {next}..{s0} of rows {r0}..{r1} are in no part"));
            }
            if s0 < next {
                return Err(format!(
                    "{name} and {last_name} both hold samples {s0}..{} of rows {r0}..{r1}",
                    next.min(s1)
                ));
            }
            next = s1;
            last_name = name;
        }
        if next < spp {
            return Err(format!("samples {next}..{spp} of rows {r0}..{r1} are in no part"));
        }
    }
    Ok(())
}

/// The `k`-th of `n` contiguous, near-equal pieces of `0..total` (the
/// first `total % n` pieces one longer).
pub fn piece(total: u64, k: u64, n: u64) -> Range<u64> {
    let (base, extra) = (total / n, total % n);
    let start = k * base + k.min(extra);
    start..start + base + u64::from(k < extra)
}

#[cfg(test)]
mod tests {
    use super::super::tests::part;
    use super::*;

    #[test]
    fn pieces_split_evenly_and_cover_the_whole() {
        for (total, n) in [(10u64, 3u64), (7, 7), (3, 4), (1000, 7)] {
            let ranges: Vec<_> = (0..n).map(|k| piece(total, k, n)).collect();
            assert_eq!(ranges[0].start, 0);
            assert_eq!(ranges[n as usize - 1].end, total);
            assert!(ranges.windows(2).all(|w| w[0].end == w[1].start));
            let sizes: Vec<u64> = ranges.iter().map(|r| r.end - r.start).collect();
            assert!(sizes.iter().max().unwrap() - sizes.iter().min().unwrap() <= 1, "{sizes:?}");
        }
    }

    #[test]
    fn merging_checks_coverage_and_sameness() {
        let named = |parts: Vec<Partial>| -> Vec<(String, Partial)> {
            parts.into_iter().enumerate().map(|(i, p)| (format!("part{i}"), p)).collect()
        };
        let whole = part(0..4, 0..5, 7);
        let split = named(vec![part(0..2, 0..5, 7), part(2..4, 0..3, 7), part(2..4, 3..5, 7)]);
        let (_, merged) = merge(&split).unwrap();
        assert_eq!(merged, whole.sums);
        let missing = merge(&named(vec![part(0..2, 0..5, 7), part(2..4, 0..3, 7)])).unwrap_err();
        assert!(missing.contains("samples 3..5 of rows 2..4 are in no part"), "{missing}");
        let overlap = merge(&named(vec![part(0..4, 0..5, 7), part(2..4, 1..2, 7)])).unwrap_err();
        assert!(overlap.contains("both hold samples 1..2 of rows 2..4"), "{overlap}");
        let seed = merge(&named(vec![part(0..2, 0..5, 7), part(2..4, 0..5, 8)])).unwrap_err();
        assert!(seed.contains("seed 8 and 7"), "{seed}");
    }
}

//! Tests of link refinement and packing.

use super::*;
use crate::SceneFile;
use crate::radiosity::{CompileParams, hierarchy, patches};

/// The stepping search finds what a binary search finds, with unequal
/// and zero areas.
#[test]
fn pick_is_the_binary_search() {
    let mut cdf = vec![0.0f64];
    for k in 0..200u64 {
        let area = [0.0, 1.0, 0.25, 7.0, 0.0, 0.5][(hierarchy::mix(k) % 6) as usize];
        cdf.push(cdf.last().unwrap() + area);
    }
    let binary = |start: usize, end: usize, u: f64| {
        let target = cdf[start] + u * (cdf[end] - cdf[start]);
        let range = &cdf[start + 1..=end];
        (start + range.partition_point(|&x| x <= target)).min(end - 1)
    };
    for (start, end) in [(0, 200), (3, 4), (10, 90), (150, 152), (0, 1)] {
        for k in 0..=1000 {
            let u = k as f64 / 1000.0 * 0.999_999;
            assert_eq!(pick(&cdf, start, end, u), binary(start, end, u), "{start}..{end}, u {u}");
        }
    }
}

/// Links made block by block are those of one refinement over all
/// receivers, with patches and with clusters receiving.
#[test]
fn blocks_do_not_change_the_links() {
    let text = include_str!("../../../../../scenes/cornell_box.toml");
    let scene = SceneFile::from_toml_str(text, None).unwrap().scene;
    let mut cut = Vec::new();
    for (index, (shape, material)) in scene.objects().iter().enumerate() {
        patches::cut(shape, *material, index as u32, 0.5, scene.bounds(), false, &mut cut);
    }
    let tree = hierarchy::build(&mut cut, 7);
    assert!(cut.len() > 1000, "{} patches", cut.len());
    for share in [0.0, 0.5] {
        let params = CompileParams { patch_size: 0.5, link_threshold: 0.02, receiver_share: share, seed: 7 };
        let build =
            |block| build_in_blocks(&cut, &tree, scene.geometry(), params.link_threshold, share, params.seed, block);
        let whole = build(u32::MAX);
        let blocked = build(37);
        assert!(whole.len() > 10_000);
        if share > 0.0 {
            let n = cut.len();
            assert!((n..whole.offsets.len() - 1).any(|r| whole.of(r).len() > 0), "clusters receive");
        }
        assert_eq!(whole, blocked, "receiver share {share}");
    }
}

/// The gather's four running sums give Σ b(source)·factor: against the
/// sum in f64, one link at a time, for lists of 0 to 40 links (each
/// remainder of four) with repeated sources, to f32 rounding.
#[test]
fn the_weighted_sum_is_the_sum_of_its_terms() {
    let b: Vec<glam::Vec3A> = (0..50u64)
        .map(|k| {
            let h = hierarchy::mix(k);
            glam::Vec3A::new((h & 0xff) as f32 / 64.0, ((h >> 8) & 0xff) as f32 / 64.0, ((h >> 16) & 0xff) as f32)
        })
        .collect();
    for n in 0..=40u64 {
        let sources: Vec<u16> = (0..n).map(|k| (hierarchy::mix(n * 100 + k) % 50) as u16).collect();
        let factors: Vec<u16> =
            (0..n).map(|k| to_bf16((hierarchy::mix(n * 1000 + k) % 1000) as f32 / 3000.0)).collect();
        let got = weighted_sum(&sources, &factors, &b, |s| s as usize);
        let mut want = glam::DVec3::ZERO;
        for (&s, &f) in sources.iter().zip(&factors) {
            want += b[s as usize].as_dvec3() * from_bf16(f) as f64;
        }
        let scale = want.abs().max_element().max(1.0);
        assert!((got.as_dvec3() - want).abs().max_element() <= 1e-5 * scale, "{n} links: {got} against {want}");
    }
}

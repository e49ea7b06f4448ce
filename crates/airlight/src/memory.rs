//! How much memory a run may take, so that sizes an input asks for (an
//! image, a mesh, a radiosity solution, an EXR header's resolution) are
//! refused up front with a message, instead of the process aborting on a
//! failed allocation or being killed by the kernel halfway through.
//!
//! The limit is the machine's available memory (`MemAvailable` in
//! /proc/meminfo), lowered by a control group's limit when there is one,
//! and by `AIRLIGHT_MEMORY_LIMIT` (bytes, or with a K, M, G or T suffix)
//! when set: a way to keep a run to its share of a shared machine.

use std::fmt;

/// The environment variable that caps the memory a run may plan for.
pub const LIMIT_VAR: &str = "AIRLIGHT_MEMORY_LIMIT";

/// A request for more memory than the limit: what, how much, the limit.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MemoryError {
    pub what: String,
    pub needed: u64,
    pub limit: u64,
    /// Where the limit comes from ("available memory", the variable, …).
    pub source: &'static str,
}

impl fmt::Display for MemoryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} needs about {}, more than the {} of {}",
            self.what,
            format_bytes(self.needed),
            format_bytes(self.limit),
            self.source
        )
    }
}

impl std::error::Error for MemoryError {}

/// Bytes a run may plan to use, and where that figure comes from; None
/// when nothing says (not Linux, no /proc).
pub fn limit() -> Option<(u64, &'static str)> {
    let mut best: Option<(u64, &'static str)> = None;
    let mut lower = |v: Option<u64>, source: &'static str| {
        if let Some(v) = v
            && best.is_none_or(|(b, _)| v < b)
        {
            best = Some((v, source));
        }
    };
    lower(meminfo_available(), "memory available on this machine");
    lower(cgroup_available(), "memory left to this control group");
    match limit_var() {
        Ok(v) => lower(v, "AIRLIGHT_MEMORY_LIMIT"),
        // A limit that cannot be read refuses everything rather than none:
        // it was meant to hold the run back. Front ends refuse it first.
        Err(_) => lower(Some(0), "AIRLIGHT_MEMORY_LIMIT, which is not a size"),
    }
    best
}

/// The limit `AIRLIGHT_MEMORY_LIMIT` sets: None when it is not set; an
/// error naming the value when it is not a size.
pub fn limit_var() -> Result<Option<u64>, String> {
    let refuse = |v: &dyn fmt::Debug| {
        format!("{LIMIT_VAR}={v:?} is not a size: give bytes, or a number with K, M, G or T (e.g. 512M)")
    };
    match std::env::var(LIMIT_VAR) {
        Err(std::env::VarError::NotPresent) => Ok(None),
        Err(std::env::VarError::NotUnicode(v)) => Err(refuse(&v)),
        Ok(v) => parse_size(&v).map(Some).ok_or_else(|| refuse(&v)),
    }
}

/// Refuses `needed` bytes for `what` when they exceed [`limit`].
pub fn check(what: impl Into<String>, needed: u64) -> Result<(), MemoryError> {
    match limit() {
        Some((limit, source)) if needed > limit => Err(MemoryError { what: what.into(), needed, limit, source }),
        _ => Ok(()),
    }
}

/// A vector of `n` copies of `value`, or an error naming `what`, the size
/// and the limit when the memory cannot be had (instead of an abort).
pub fn try_vec<T: Clone>(what: &str, n: usize, value: T) -> Result<Vec<T>, MemoryError> {
    let bytes = (n as u64).saturating_mul(size_of::<T>() as u64);
    check(what, bytes)?;
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| MemoryError {
        what: what.into(),
        needed: bytes,
        limit: limit().map_or(0, |l| l.0),
        source: "memory the allocator could give",
    })?;
    v.resize(n, value);
    Ok(v)
}

/// `MemAvailable` from /proc/meminfo, in bytes.
fn meminfo_available() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// A control group's limit less its usage (cgroup v2, else v1), when limited.
fn cgroup_available() -> Option<u64> {
    let read = |p: &str| std::fs::read_to_string(p).ok().and_then(|s| s.trim().parse::<u64>().ok());
    let (max, used) = match read("/sys/fs/cgroup/memory.max") {
        Some(max) => (max, read("/sys/fs/cgroup/memory.current")?),
        None => {
            (read("/sys/fs/cgroup/memory/memory.limit_in_bytes")?, read("/sys/fs/cgroup/memory/memory.usage_in_bytes")?)
        }
    };
    // v1 reports "no limit" as a number near 2⁶³.
    (max < 1 << 60).then(|| max.saturating_sub(used))
}

/// "123", "64K", "1.5G", … in bytes (powers of 1024).
pub fn parse_size(s: &str) -> Option<u64> {
    let s = s.trim();
    let (number, unit) = match s.char_indices().find(|(_, c)| c.is_ascii_alphabetic()) {
        Some((i, _)) => (&s[..i], s[i..].trim_end_matches(['B', 'b', 'i'])),
        None => (s, ""),
    };
    let scale = match unit.to_ascii_uppercase().as_str() {
        "" => 1u64,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        "T" => 1 << 40,
        _ => return None,
    };
    let v: f64 = number.trim().parse().ok()?;
    (v.is_finite() && v >= 0.0).then(|| (v * scale as f64).min(u64::MAX as f64) as u64)
}

/// Bytes in the largest binary unit that keeps the figure ≥ 1: "3.2 GiB".
pub fn format_bytes(bytes: u64) -> String {
    const UNITS: [&str; 7] = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = bytes as f64;
    let mut unit = 0;
    while v >= 1024.0 && unit + 1 < UNITS.len() {
        v /= 1024.0;
        unit += 1;
    }
    if unit == 0 { format!("{bytes} bytes") } else { format!("{v:.1} {}", UNITS[unit]) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_print_in_binary_units() {
        assert_eq!(parse_size("123"), Some(123));
        assert_eq!(parse_size("64K"), Some(65536));
        assert_eq!(parse_size("1.5GiB"), Some(3 << 29));
        assert_eq!(parse_size("2 m"), Some(2 << 20));
        assert_eq!(parse_size("lots"), None);
        assert_eq!(parse_size("-1"), None);
        assert_eq!(format_bytes(512), "512 bytes");
        assert_eq!(format_bytes(3 << 29), "1.5 GiB");
    }

    #[test]
    fn this_machine_reports_a_limit_and_refuses_an_exabyte() {
        let (limit, _) = limit().expect("Linux has /proc/meminfo");
        assert!(limit > 1 << 20);
        let e = check("the test", 1 << 60).unwrap_err();
        assert!(e.to_string().starts_with("the test needs about 1.0 EiB, more than the "), "{e}");
        assert!(try_vec("a huge vector", usize::MAX / 16, 0u8).is_err());
        assert_eq!(try_vec("a small vector", 3, 7u8).unwrap(), vec![7, 7, 7]);
    }
}

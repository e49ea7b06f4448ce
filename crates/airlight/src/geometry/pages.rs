//! Large pages for the arrays that rays read at random.
//!
//! A ray through a mesh of a million triangles visits a few dozen nodes and
//! leaves scattered over tens of megabytes. With 4 KB pages nearly every
//! visit also misses the processor's page-translation cache (one to a few
//! thousand entries: a few megabytes of 4 KB pages) and waits on a page walk
//! before its fetch can start; with 2 MB pages the same entries cover
//! gigabytes. Linux gives 2 MB pages to anonymous memory that asks for
//! them (`madvise(MADV_HUGEPAGE)`) when transparent huge pages are set to
//! `madvise`, as on Debian; `MADV_COLLAPSE` (Linux 6.1) moves memory
//! already written into them at once, whatever that setting. Both are
//! hints: where the system cannot follow them (an older kernel, huge
//! pages turned off, another system) nothing changes, and the contents
//! never do.

/// Smallest array worth the system calls: below a few 2 MB pages the
/// translation cache holds it anyway.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const WORTHWHILE: usize = 8 << 20;

/// An empty vector with room for `len` elements whose memory asks for
/// huge pages before it is first written (so that it is born in them,
/// without a copy).
pub(super) fn vec_in_huge_pages<T>(len: usize) -> Vec<T> {
    let v = Vec::with_capacity(len);
    advise(v.as_ptr(), len * std::mem::size_of::<T>(), false);
    v
}

/// The items collected into a vector born in huge pages.
pub(super) fn collect_in_huge_pages<T>(items: impl ExactSizeIterator<Item = T>) -> Vec<T> {
    let mut v = vec_in_huge_pages(items.len());
    v.extend(items);
    v
}

/// Moves the memory of `data`, already written, into huge pages where it
/// is not in them yet (the nodes, whose count is known only once built).
pub(super) fn move_to_huge_pages<T>(data: &[T]) {
    advise(data.as_ptr(), std::mem::size_of_val(data), true);
}

/// The size of a huge page on x86-64 and most 64-bit Linux systems.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const HUGE_PAGE: usize = 2 << 20;

/// Asks for huge pages for the whole 2 MB pages within `bytes` from
/// `start`, and with `collapse` for their contents to move now.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn advise<T>(start: *const T, bytes: usize, collapse: bool) {
    if bytes < WORTHWHILE {
        return;
    }
    let first = (start as usize).next_multiple_of(HUGE_PAGE);
    let end = (start as usize + bytes) / HUGE_PAGE * HUGE_PAGE;
    if end <= first {
        return;
    }
    let (ptr, len) = (first as *mut libc::c_void, end - first);
    // SAFETY: [first, end) lies within one live allocation of the caller's;
    // these advices change how its pages are backed, never their contents
    // (they are not MADV_DONTNEED or MADV_FREE). A failure (EINVAL on an
    // old kernel, EAGAIN without free huge pages) leaves the memory as it
    // was: correct, only slower.
    unsafe {
        libc::madvise(ptr, len, libc::MADV_HUGEPAGE);
        if collapse {
            libc::madvise(ptr, len, libc::MADV_COLLAPSE);
        }
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn advise<T>(_start: *const T, _bytes: usize, _collapse: bool) {}

#[cfg(test)]
mod tests {
    use super::*;

    /// Advised memory keeps what is written to it, whether or not the
    /// system gave it huge pages.
    #[test]
    fn advised_vectors_keep_their_contents() {
        let n = (6 << 20) + 12345; // 24 MB of u32
        let v: Vec<u32> = collect_in_huge_pages((0..n as u32).map(|i| i.wrapping_mul(2_654_435_761)));
        move_to_huge_pages(&v);
        assert!(v.iter().enumerate().all(|(i, &x)| x == (i as u32).wrapping_mul(2_654_435_761)));
    }
}

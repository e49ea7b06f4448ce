//! Buffers reused across calls on one thread, so that work done per ray or
//! per block of samples does not allocate each time.

use std::cell::RefCell;
use std::thread::LocalKey;

/// Runs `f` with this thread's buffer in `cell`, or with a fresh one when a
/// caller further up the stack holds it already (a nested call).
pub(crate) fn with_scratch<T: Default, R>(cell: &'static LocalKey<RefCell<T>>, f: impl FnOnce(&mut T) -> R) -> R {
    cell.with(|buffer| match buffer.try_borrow_mut() {
        Ok(mut buffer) => f(&mut buffer),
        Err(_) => f(&mut T::default()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    thread_local! {
        static BUFFER: RefCell<Vec<u32>> = const { RefCell::new(Vec::new()) };
    }

    #[test]
    fn the_buffer_is_kept_between_calls_and_a_nested_call_gets_its_own() {
        with_scratch(&BUFFER, |b| {
            b.clear();
            b.push(7);
        });
        // The same buffer again, with what the last call left in it.
        assert_eq!(with_scratch(&BUFFER, |b| b.clone()), [7]);
        let (outer, inner) = with_scratch(&BUFFER, |outer| {
            outer.push(8);
            let inner = with_scratch(&BUFFER, |inner| {
                inner.push(1);
                inner.clone()
            });
            (outer.clone(), inner)
        });
        assert_eq!((outer, inner), (vec![7, 8], vec![1]));
    }
}

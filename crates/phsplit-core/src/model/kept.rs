//! What a thread keeps of functions of time that a collocation asks for again: the stage times
//! of a sub-step recur at every pass of its fixed point (a sea's time factors, a gust speed, a
//! moving set point). Values are kept by the identity of the object that computes them and by
//! the bits of the time, so a value asked again is the same bits as computed, however often,
//! in whatever order and on whichever thread it is asked.

use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};
use std::thread::LocalKey;

/// An identity for the per-thread memos: unique per object built (copies share it, with the
/// same contents, which must not change after). Equal for any two, so that it does not change
/// which objects compare equal.
#[derive(Debug, Clone, Copy)]
pub struct Identity(u64);

static NEXT: AtomicU64 = AtomicU64::new(1);

impl Identity {
    /// A new identity (never 0, which marks an empty slot).
    pub fn new() -> Self {
        Identity(NEXT.fetch_add(1, Ordering::Relaxed))
    }
    pub fn get(self) -> u64 {
        self.0
    }
}

impl Default for Identity {
    fn default() -> Self {
        Self::new()
    }
}

impl PartialEq for Identity {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// The last `N` values of functions of time a thread computed, the newest first:
/// `(identity, time's bits, value)`.
pub type Recent<T, const N: usize> = Cell<[(u64, u64, T); N]>;

/// The value at `t` of the object `id`: kept in `cell` if this thread computed it among the
/// last `N`, else `compute()`, kept in place of the oldest.
pub fn at_time<T: Copy + 'static, const N: usize>(
    cell: &'static LocalKey<Recent<T, N>>,
    id: Identity,
    t: f64,
    compute: impl FnOnce() -> T,
) -> T {
    let (key, bits) = (id.0, t.to_bits());
    let mut last = cell.with(|c| c.get());
    if let Some(&(_, _, v)) = last.iter().find(|(k, b, _)| *k == key && *b == bits) {
        return v;
    }
    let v = compute();
    last.rotate_right(1);
    last[0] = (key, bits, v);
    cell.with(|c| c.set(last));
    v
}

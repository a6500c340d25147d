//! A raw shared pointer: a mutable slice every thread of a parallel sweep (XPBD's colours and
//! slabs, VBD's node colours) writes, each thread its own disjoint entries.

/// A mutable slice shared across threads through a raw pointer: the parallel sweeps hand one
/// copy to every thread of a colour (or slab), and those threads touch disjoint entries (no two
/// elements of a colour share a node; each element owns its multipliers).
/// That disjointness, which the type cannot check, is what every `unsafe` access promises.
/// Indices are checked against the length (a panic, never an out-of-bounds access); the hot
/// loops that have already checked an index read and write through [`SharedMut::ptr`].
pub struct SharedMut<T> {
    ptr: *mut T,
    len: usize,
}

impl<T> Clone for SharedMut<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for SharedMut<T> {}

// SAFETY: shared across the threads of one colour, which touch disjoint entries.
unsafe impl<T: Send> Send for SharedMut<T> {}
unsafe impl<T: Send> Sync for SharedMut<T> {}

impl<T> SharedMut<T> {
    pub fn new(slice: &mut [T]) -> Self {
        Self { ptr: slice.as_mut_ptr(), len: slice.len() }
    }

    /// Number of entries.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The first entry's address (for accesses whose index the caller has checked against
    /// [`SharedMut::len`]).
    #[inline(always)]
    pub fn ptr(&self) -> *mut T {
        self.ptr
    }

    /// Entry `i` (panics when `i ≥ len`).
    ///
    /// # Safety
    /// No other thread may write entry `i` meanwhile, and the slice must still be alive.
    #[inline(always)]
    pub unsafe fn read(&self, i: usize) -> T
    where
        T: Copy,
    {
        assert!(i < self.len);
        // SAFETY: in bounds (checked); the caller excludes concurrent writes.
        unsafe { self.ptr.add(i).read() }
    }

    /// Writes entry `i` (panics when `i ≥ len`).
    ///
    /// # Safety
    /// No other thread may access entry `i` meanwhile, and the slice must still be alive.
    #[inline(always)]
    pub unsafe fn write(&self, i: usize, value: T) {
        assert!(i < self.len);
        // SAFETY: in bounds (checked); the caller excludes concurrent access.
        unsafe { self.ptr.add(i).write(value) }
    }

    /// Entries `start..start + len` as a mutable slice (panics when out of bounds).
    ///
    /// # Safety
    /// No other thread may access that range while the returned slice lives, and the slice
    /// must still be alive.
    #[allow(clippy::mut_from_ref)] // disjoint ranges handed to different threads: the point
    #[inline(always)]
    pub unsafe fn slice_mut(&self, start: usize, len: usize) -> &mut [T] {
        assert!(start <= self.len && len <= self.len - start);
        // SAFETY: in bounds (checked); the caller excludes concurrent access.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(start), len) }
    }
}

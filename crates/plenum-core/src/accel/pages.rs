//! Arrays that a traversal reads at random, kept on 2 MiB pages where Linux offers them.
//!
//! An incoherent ray lands on a new 4 KiB page at nearly every node and leaf of a large
//! structure, and each page the TLB does not hold costs a walk of the page tables before the
//! load can start. Transparent huge pages cover 512 times as much per TLB entry, so that a
//! structure of tens of megabytes stays mapped. Linux gives them to memory that asks
//! (`madvise(MADV_HUGEPAGE)`, when /sys/kernel/mm/transparent_hugepage/enabled says
//! `madvise`), as Embree's allocator asks for its BVHs. Elsewhere, or for an array a
//! second-level TLB maps whole in 4 KiB pages, the array is an ordinary allocation: on
//! structures of a few megabytes (the bunny's and the dragon's, traced by two threads) huge
//! pages measured up to 8 % slower, on the 70 MB level-8 icosphere up to 14 % faster.

use std::ops::{Deref, DerefMut};
use std::ptr::NonNull;

/// The size of a huge page.
#[cfg_attr(not(target_os = "linux"), allow(dead_code))]
const HUGE_PAGE: usize = 2 << 20;

/// The least array put on huge pages: what 4096 TLB entries (a recent second-level TLB's)
/// map in 4 KiB pages.
#[cfg_attr(not(target_os = "linux"), allow(dead_code))]
const HUGE_PAGES_FROM: usize = 16 << 20;

/// A fixed-length array of `T`; from [`HUGE_PAGES_FROM`] bytes up, in a mapping of its own
/// that starts on a huge page and asks for them.
pub struct LargeArray<T: Copy> {
    ptr: NonNull<T>,
    len: usize,
    /// Where the array's memory came from, to give it back.
    source: Source,
}

enum Source {
    /// An ordinary allocation (or none, for no bytes): the `Vec` the array was made from.
    Vec { capacity: usize },
    /// An anonymous mapping of `bytes` from `base`, of which the array is the aligned part.
    #[cfg(target_os = "linux")]
    Mapped {
        base: *mut libc::c_void,
        bytes: usize,
    },
}

// SAFETY: a LargeArray owns its elements like a Vec; sharing or sending it is as safe as
// sharing or sending the `T`s.
unsafe impl<T: Copy + Send> Send for LargeArray<T> {}
unsafe impl<T: Copy + Sync> Sync for LargeArray<T> {}

impl<T: Copy> LargeArray<T> {
    /// The items of `items`, moved to huge pages if there are enough of them.
    pub fn from_vec(items: Vec<T>) -> LargeArray<T> {
        #[cfg(target_os = "linux")]
        if let Some(array) = Self::mapped(&items) {
            return array;
        }
        let mut items = std::mem::ManuallyDrop::new(items);
        LargeArray {
            // SAFETY: a Vec's pointer is never null.
            ptr: unsafe { NonNull::new_unchecked(items.as_mut_ptr()) },
            len: items.len(),
            source: Source::Vec {
                capacity: items.capacity(),
            },
        }
    }

    /// A copy of `items` in a fresh mapping that starts on a huge page and asks for huge
    /// pages, or None where it is smaller than [`HUGE_PAGES_FROM`] or the system refuses.
    #[cfg(target_os = "linux")]
    fn mapped(items: &[T]) -> Option<LargeArray<T>> {
        let size = std::mem::size_of_val(items);
        if size < HUGE_PAGES_FROM || std::mem::align_of::<T>() > HUGE_PAGE {
            return None;
        }
        // One huge page more than needed, so that an aligned start lies within.
        let bytes = size.checked_add(HUGE_PAGE)?;
        // SAFETY: a fresh private anonymous mapping; nothing else refers to it.
        let base = unsafe {
            libc::mmap(
                std::ptr::null_mut(),
                bytes,
                libc::PROT_READ | libc::PROT_WRITE,
                libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
                -1,
                0,
            )
        };
        if base == libc::MAP_FAILED {
            return None;
        }
        let start = (base as usize).next_multiple_of(HUGE_PAGE) as *mut T;
        // SAFETY: [start, start + size) lies within the mapping, whose pages are untouched:
        // advised now, they are huge pages when first written. The advice is only a hint,
        // so its failure (a kernel without transparent huge pages) is no error.
        unsafe {
            libc::madvise(start as *mut libc::c_void, size, libc::MADV_HUGEPAGE);
            std::ptr::copy_nonoverlapping(items.as_ptr(), start, items.len());
        }
        Some(LargeArray {
            // SAFETY: inside a mapping that did not fail, so not null.
            ptr: unsafe { NonNull::new_unchecked(start) },
            len: items.len(),
            source: Source::Mapped { base, bytes },
        })
    }
}

impl<T: Copy> Drop for LargeArray<T> {
    fn drop(&mut self) {
        match self.source {
            Source::Vec { capacity } => {
                // SAFETY: the parts of the Vec the array was made from, given back once.
                drop(unsafe { Vec::from_raw_parts(self.ptr.as_ptr(), self.len, capacity) });
            }
            #[cfg(target_os = "linux")]
            Source::Mapped { base, bytes } => {
                // SAFETY: the mapping made for this array, unmapped once; `T: Copy` needs
                // no drop.
                unsafe { libc::munmap(base, bytes) };
            }
        }
    }
}

impl<T: Copy> Deref for LargeArray<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        // SAFETY: `len` initialised elements from `ptr`, owned by the array.
        unsafe { std::slice::from_raw_parts(self.ptr.as_ptr(), self.len) }
    }
}

impl<T: Copy> DerefMut for LargeArray<T> {
    fn deref_mut(&mut self) -> &mut [T] {
        // SAFETY: as for `deref`, and `&mut self` makes the borrow unique.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.as_ptr(), self.len) }
    }
}

impl<T: Copy> Default for LargeArray<T> {
    fn default() -> LargeArray<T> {
        LargeArray::from_vec(Vec::new())
    }
}

impl<T: Copy> Clone for LargeArray<T> {
    fn clone(&self) -> LargeArray<T> {
        LargeArray::from_vec(self.to_vec())
    }
}

impl<T: Copy> From<Vec<T>> for LargeArray<T> {
    fn from(items: Vec<T>) -> LargeArray<T> {
        LargeArray::from_vec(items)
    }
}

impl<T: Copy> FromIterator<T> for LargeArray<T> {
    fn from_iter<I: IntoIterator<Item = T>>(items: I) -> LargeArray<T> {
        LargeArray::from_vec(items.into_iter().collect())
    }
}

impl<T: Copy + std::fmt::Debug> std::fmt::Debug for LargeArray<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_and_large_arrays_hold_what_they_were_made_from() {
        for len in [
            0,
            1,
            1000,
            3 * HUGE_PAGE / 4 + 7,
            HUGE_PAGES_FROM / 4 - 1,
            HUGE_PAGES_FROM / 4,
            HUGE_PAGES_FROM / 4 + 7,
        ] {
            let items: Vec<u32> = (0..len as u32)
                .map(|i| i.wrapping_mul(2_654_435_761))
                .collect();
            let mut array = LargeArray::from_vec(items.clone());
            assert_eq!(&array[..], &items[..]);
            if len > 0 {
                array[len - 1] = 7;
                assert_eq!(array[len - 1], 7);
            }
            let copy = array.clone();
            assert_eq!(&copy[..], &array[..]);
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_large_array_starts_on_a_huge_page() {
        let array = LargeArray::from_vec(vec![1u8; HUGE_PAGES_FROM + 1]);
        assert!(matches!(array.source, Source::Mapped { .. }));
        assert_eq!(array.as_ptr() as usize % HUGE_PAGE, 0);
        assert!(array.iter().all(|&b| b == 1));
        let small = LargeArray::from_vec(vec![1u8; HUGE_PAGES_FROM - 1]);
        assert!(matches!(small.source, Source::Vec { .. }));
    }
}

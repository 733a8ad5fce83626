//! The CLI's allocator: the system's, asking Linux for transparent huge
//! pages on large blocks (issue 15).
//!
//! A 2 M-triangle scan fills about 130 MB of fresh memory (the file's
//! bytes, the mesh, its index and their transient arrays). In 4 KiB pages
//! that is some 40 000 page faults, and on a virtual machine each costs
//! microseconds: a fifth of `pcpp plan`'s time went to the kernel. A block
//! of 8 MiB or more is marked `MADV_HUGEPAGE`, so it faults in 2 MiB at a
//! time where the kernel allows it (`/sys/kernel/mm/transparent_hugepage`
//! set to `madvise` or `always`); elsewhere the advice is ignored. Only
//! the whole 2 MiB pages inside a block are marked, so no memory outside
//! it is touched, and the advice changes no byte of any result.

use std::alloc::{GlobalAlloc, Layout, System};

/// The system allocator, with the advice on large blocks.
pub struct HugePages;

/// A transparent huge page on x86-64 and aarch64 (4 KiB base pages).
const HUGE_PAGE: usize = 2 << 20;

/// Blocks from this size on are advised: a few huge pages at least, so the
/// partial pages at their ends are a small share.
const ADVISED_FROM: usize = 4 * HUGE_PAGE;

fn advise(ptr: *mut u8, size: usize) {
    if ptr.is_null() || size < ADVISED_FROM {
        return;
    }
    let start = (ptr as usize).next_multiple_of(HUGE_PAGE);
    let end = (ptr as usize + size) & !(HUGE_PAGE - 1);
    if end > start {
        // SAFETY: [start, end) lies inside the block just allocated, which
        // is mapped; MADV_HUGEPAGE changes how it is backed, not its
        // contents. A failure (no THP support) leaves it as it was.
        unsafe {
            libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
        }
    }
}

// SAFETY: every call is forwarded to `System` with the same arguments; the
// advice only concerns the memory `System` returned.
unsafe impl GlobalAlloc for HugePages {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let ptr = unsafe { System.alloc(layout) };
        advise(ptr, layout.size());
        ptr
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let ptr = unsafe { System.alloc_zeroed(layout) };
        advise(ptr, layout.size());
        ptr
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let new = unsafe { System.realloc(ptr, layout, new_size) };
        advise(new, new_size);
        new
    }
}

//! Transparent huge pages for the BVH's large arrays. Incoherent rays touch nodes and leaf
//! blocks all over tens of megabytes; with 4 KiB pages nearly every visit also misses the TLB
//! and walks the page table. Embree asks Linux for 2 MiB pages on its BVH memory
//! (`madvise(MADV_HUGEPAGE)` in its `os_malloc`); this module does the same for ours, so that
//! the comparison is between the trees, not the page sizes. Where the kernel declines (THP
//! disabled, no memory to compact) the arrays stay on small pages and only speed differs.
#![allow(unsafe_code)] // one `madvise` system call on memory this module owns.

/// Arrays smaller than one huge page stay where they are.
const HUGE_PAGE_BYTES: usize = 2 << 20;

/// `src` moved into a fresh allocation that the kernel is asked to back with huge pages
/// before it is written (Linux; elsewhere, and for small arrays, `src` itself).
pub(super) fn on_huge_pages<T: Copy>(src: Vec<T>) -> Vec<T> {
    let bytes = std::mem::size_of_val(src.as_slice());
    if bytes < HUGE_PAGE_BYTES || !cfg!(target_os = "linux") {
        return src;
    }
    let mut out: Vec<T> = Vec::with_capacity(src.len());
    advise_huge(out.as_mut_ptr().cast::<u8>(), bytes);
    out.extend_from_slice(&src);
    out
}

#[cfg(target_os = "linux")]
fn advise_huge(start: *mut u8, bytes: usize) {
    let page = 4096;
    let addr = start as usize;
    let aligned = addr.next_multiple_of(page);
    let len = (addr + bytes).saturating_sub(aligned) / page * page;
    if len == 0 {
        return;
    }
    // SAFETY: `[aligned, aligned + len)` lies inside the allocation `start..start + bytes`
    // this function's caller owns and has not yet written; MADV_HUGEPAGE only changes how
    // the kernel backs those pages, never their contents. A failure (EINVAL where THP is
    // not built in) leaves small pages, which is correct, only slower.
    unsafe {
        libc::madvise(aligned as *mut libc::c_void, len, libc::MADV_HUGEPAGE);
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge(_start: *mut u8, _bytes: usize) {}

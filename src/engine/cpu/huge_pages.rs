//! Huge pages under the shapes that the pair stage reads at random.
//!
//! Where every particle has a shape of its own, a contact reads two shapes' vertices
//! and planes scattered over megabytes of heap (scene (d) of `talus bench`: 10 648
//! shapes, 13 MB), each in a 4 KB page of its own: the page walks add to the misses
//! the prefetches wait on. The 2 MB pages that hold the distinct shapes are asked
//! to be backed as such (`MADV_HUGEPAGE`) and merged at once (`MADV_COLLAPSE`, Linux
//! 6.1 and later). Both are hints: where the kernel declines them (an older kernel,
//! transparent huge pages switched off) nothing changes but the speed, and no data
//! moves in the process's view.

use std::ops::Range;

/// The size of a huge page on x86_64 and aarch64 with 4 KB base pages.
const HUGE_PAGE: usize = 2 << 20;

/// Asks for the huge pages that hold `ranges` (addresses of live heap data) to be
/// backed as such; returns how many were asked for. The pages are taken in runs of
/// neighbours, so that data spread over heaps far apart (one per thread) asks for
/// nothing between them.
pub(super) fn back_with_huge_pages(ranges: impl Iterator<Item = Range<usize>>) -> usize {
    let mut pages: Vec<usize> = ranges
        .filter(|r| !r.is_empty())
        .flat_map(|r| r.start / HUGE_PAGE..=(r.end - 1) / HUGE_PAGE)
        .collect();
    pages.sort_unstable();
    pages.dedup();
    for run in pages.chunk_by(|a, b| b - a == 1) {
        advise(run[0] * HUGE_PAGE..(run[run.len() - 1] + 1) * HUGE_PAGE);
    }
    pages.len()
}

/// Asks for `span` (whole huge pages) to be backed by huge pages, and to be merged
/// now.
#[cfg(target_os = "linux")]
fn advise(span: Range<usize>) {
    let at = std::ptr::without_provenance_mut::<libc::c_void>(span.start);
    // SAFETY: madvise with these advices changes how memory is backed, never what
    // it holds (whatever mapping the span's edges reach into); where part of the
    // span is not mapped it advises the mapped parts and reports ENOMEM, which,
    // like a kernel that declines, changes nothing but the speed.
    unsafe {
        libc::madvise(at, span.len(), libc::MADV_HUGEPAGE);
        libc::madvise(at, span.len(), libc::MADV_COLLAPSE);
    }
}

#[cfg(not(target_os = "linux"))]
fn advise(_span: Range<usize>) {}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    /// Kilobytes of huge pages in the mapping that holds address `at`, from
    /// `/proc/self/smaps`.
    fn huge_kb_at(at: usize) -> usize {
        let smaps = std::fs::read_to_string("/proc/self/smaps").unwrap();
        let mut inside = false;
        for line in smaps.lines() {
            if let Some((range, _)) = line.split_once(' ')
                && let Some((a, b)) = range.split_once('-')
                && let (Ok(a), Ok(b)) = (usize::from_str_radix(a, 16), usize::from_str_radix(b, 16))
            {
                inside = (a..b).contains(&at);
            } else if inside && let Some(kb) = line.strip_prefix("AnonHugePages:") {
                return kb.trim().trim_end_matches(" kB").parse().unwrap();
            }
        }
        0
    }

    /// Where the kernel offers transparent huge pages on request, 8 MB of data
    /// written in 4 KB pages are backed by at least three huge pages after the
    /// request (the whole ones inside it), and hold what they held.
    #[test]
    fn data_in_small_pages_moves_to_huge_ones_where_the_kernel_offers_them() {
        let offered = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled")
            .is_ok_and(|mode| !mode.contains("[never]"));
        let data: Vec<u64> = (0..1u64 << 20).collect();
        let at = data.as_ptr().addr();
        let asked = back_with_huge_pages(std::iter::once(at..at + (8 << 20)));
        assert!(
            (4..=5).contains(&asked),
            "8 MB lie in four or five 2 MB pages"
        );
        if offered {
            let kb = huge_kb_at(at + (4 << 20));
            assert!(kb >= 3 * 2048, "{kb} kB of huge pages under the data");
        }
        assert!(data.iter().enumerate().all(|(k, &x)| x == k as u64));
    }
}

#pragma once
/// \file
/// Transparent-huge-page hints for large buffers.
///
/// A fresh anonymous page costs a page fault when it is first written: one per 4 KiB. Under a
/// hypervisor a fault can cost several microseconds, and at a million particles the relaxation
/// writes gigabytes of fresh buffers (multigrid hierarchy, positions, frames): measured on the
/// project's 2-core virtual machines, the multigrid set-up at a million unknowns took 2.5 s with
/// 4 KiB pages and 0.7 s with the whole process on huge pages.
/// Linux distributions commonly set transparent huge pages to "madvise": 2 MiB pages (one fault
/// per 2 MiB) only where the program asks for them. `advise_huge_pages` asks, for the part of a
/// buffer that covers whole 2 MiB pages; it must be called after allocating and before the first
/// write. It changes nothing else: on other systems, for small buffers, or when the kernel refuses,
/// it does nothing.

#include <cstddef>
#include <vector>

namespace elastic {

/// Buffers below this size are left alone (a huge page would mostly hold other data).
inline constexpr std::size_t kHugePageMinimum = std::size_t{4} << 20;

/// madvise(MADV_HUGEPAGE) on the 2 MiB-aligned pages inside [data, data + bytes). Never fails.
void advise_huge_pages(const void* data, std::size_t bytes) noexcept;

/// `v` = `n` copies of `value`, in storage advised before it is written.
template <typename T>
void assign_huge(std::vector<T>& v, std::size_t n, const T& value = T()) {
  std::vector<T> fresh;
  fresh.reserve(n);
  advise_huge_pages(fresh.data(), n * sizeof(T));
  fresh.assign(n, value);
  v.swap(fresh);
}

/// Resizes an Eigen matrix or vector (fresh storage, uninitialised) and advises it.
template <typename Matrix>
void resize_huge(Matrix& m, long rows, long cols) {
  m.resize(rows, cols);
  advise_huge_pages(m.data(), static_cast<std::size_t>(m.size()) * sizeof(*m.data()));
}

}  // namespace elastic

// Large blocks on transparent huge pages. Replaces the global operator new (so every std::vector
// of every executable that links karst gets it): a block of 4 MiB or more is advised
// MADV_HUGEPAGE before it is first touched, so the kernel backs its aligned middle with 2 MiB
// pages, one page fault where 4 KiB pages take 512. Where faults are dear (virtual machines), a
// fresh array of particle data otherwise costs more to touch than to compute with; see
// bench/results/2core/bench_surface_320k.csv. Smaller blocks, aligned new and the sanitizer
// builds (whose allocator checks new against delete) keep the library's operator new.
#include <sys/mman.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <new>

#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)

namespace {

constexpr std::uintptr_t k_huge_page = std::uintptr_t(2) << 20;

void* allocate(std::size_t bytes) {
    void* p = std::malloc(bytes > 0 ? bytes : 1);
    if (!p) throw std::bad_alloc();
    if (bytes >= 2 * k_huge_page) {
        const std::uintptr_t at = reinterpret_cast<std::uintptr_t>(p);
        const std::uintptr_t begin = (at + k_huge_page - 1) & ~(k_huge_page - 1);
        const std::uintptr_t end = (at + bytes) & ~(k_huge_page - 1);
        // Advice only: where the kernel has no huge pages, the block keeps small ones (and
        // errno stays as it was).
        const int saved = errno;
        if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
        errno = saved;
    }
    return p;
}

}  // namespace

void* operator new(std::size_t bytes) {
    return allocate(bytes);
}
void* operator new[](std::size_t bytes) {
    return allocate(bytes);
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete[](void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
    std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
    std::free(p);
}

#endif

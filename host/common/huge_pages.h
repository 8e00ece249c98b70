// Transparent huge pages for the large arrays a scene is read into: a page fault per 4 KiB of
// a few hundred MiB of triangles dominates reading a big scene on a virtual machine, where a
// fault is expensive; with 2 MiB pages there are 512 times fewer.
#pragma once

#include <cstddef>

namespace pt {

// Asks the kernel to back the 2 MiB-aligned pages inside [data, data + bytes) with huge pages
// when they are first touched (Linux's madvise MADV_HUGEPAGE, which the default "madvise"
// setting of transparent huge pages honours). A hint: nothing happens elsewhere, or where the
// kernel refuses, and ranges under 2 MiB are left alone.
void adviseHugePages(void* data, std::size_t bytes);

}  // namespace pt

// The pages of freed buffers handed back to the system between the diagnosis's stages.
#pragma once

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace ftstack::diag {

/// Returns the whole free pages of the heap to the system (their addresses stay reserved). ftdiag
/// keeps freed n × N buffers in its heap for the next fit (tools/ftdiag), which is fast but lets
/// the heap's resident size follow how the threads' buffers happened to interleave: between the
/// stages where most buffers are freed at once (the reading's columns after the context is made,
/// the candidates' predictions after the pairs) this makes the peak what the stages hold, not
/// what earlier ones left behind. A no-op where the C library has no such call.
inline void ReturnFreedPages() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace ftstack::diag

// The pages of freed buffers handed back to the system between the diagnosis's stages.
#pragma once

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace ftstack::diag {

/// Returns the whole free pages of the heap to the system (their addresses stay reserved). ftdiag
/// keeps freed n × N buffers in its heap for the next fit (tools/ftdiag), which is fast but lets
/// the heap's resident size follow how the threads' buffers happened to interleave. Called
/// between the stages where most buffers are freed at once (the reading's columns after the
/// context is made, the candidates' predictions after the pairs), it keeps pages an earlier stage
/// left free out of a later stage's resident size; the peak still scatters with the threads'
/// timing within a stage (docs/diagnosis.md). It costs the faults of those pages when reused.
/// A no-op where the C library has no such call.
inline void ReturnFreedPages() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace ftstack::diag

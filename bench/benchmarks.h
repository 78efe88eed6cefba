// The benchmark groups of camhead_benchmarks, registered at start-up.
#pragma once

namespace camhead::bench {

void register_frame_benchmarks();      // frame_benchmarks.cpp: Frame/{gpu,cpu}/...
void register_live_frame_benchmarks(); // live_frame_benchmarks.cpp: LiveFrame/...
void register_micro_benchmarks();      // micro_benchmarks.cpp: Micro/...

} // namespace camhead::bench

#version 460
#extension GL_GOOGLE_include_directive : require
// One thread: turns queue sizes into indirect dispatch sizes and resets the queues about to fill.
layout(local_size_x = 1) in;
#include "../include/kernel_prelude.glsl"

void main() {
  if (push.mode == 0u) {  // before shade
    uint items = counters[kCounterRayQueue0 + push.cur];
    indirect_args[0] = (items + 63u) / 64u;
    if (params.collect_stats != 0u) {  // shade's lane fill: queue entries / launched lanes
      add_stat64(kCounterStatShadeItems, items);
      add_stat64(kCounterStatShadeLanes, indirect_args[0] * 64u);
    }
    indirect_args[1] = 1u;
    indirect_args[2] = 1u;
    counters[kCounterRayQueue0 + out_queue()] = 0u;
    counters[kCounterShadowQueue] = 0u;
  } else {  // before connect and extend
    indirect_args[3] = (counters[kCounterShadowQueue] + 63u) / 64u;
    indirect_args[4] = 1u;
    indirect_args[5] = 1u;
    indirect_args[6] = (counters[kCounterRayQueue0 + out_queue()] + 63u) / 64u;
    indirect_args[7] = 1u;
    indirect_args[8] = 1u;
  }
}

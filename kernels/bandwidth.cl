// Copy kernel: the benchmark measures the device's achievable memory bandwidth with it, in the
// same run as the simulation kernels, to state what fraction of it a step reaches.
kernel void copy_bandwidth(global const real4* src, global real4* dst, uint n) {
  const uint i = get_global_id(0);
  if (i < n) dst[i] = src[i];
}

// Holds the queue for about n dependent multiply-adds per work-item (one work-group), so that the
// host can enqueue a batch of steps behind it: the batch then runs at the device's own pace
// (voxbreast bench --profile, "device alone").
kernel void hold_queue(global float* scratch, uint n) {
  float s = scratch[get_global_id(0)];
  for (uint i = 0; i < n; ++i) s = s * 0.99999f + 0.5f;
  scratch[get_global_id(0)] = s;
}

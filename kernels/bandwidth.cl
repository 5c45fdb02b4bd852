// Copy kernel: the benchmark measures the device's achievable memory bandwidth with it, in the
// same run as the simulation kernels, to state what fraction of it a step reaches.
kernel void copy_bandwidth(global const real4* src, global real4* dst, uint n) {
  const uint i = get_global_id(0);
  if (i < n) dst[i] = src[i];
}

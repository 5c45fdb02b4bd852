#pragma once
/// Which OpenCL devices a sweep's workers drive (docs/SWEEP.md, "Devices").
#include <string>
#include <vector>

#include "engine/sim/opencl_runtime.hpp"

namespace vb {

/// The devices named by --devices:
///   ""          one device, chosen as for `simulate` ($VOXBREAST_DEVICE, else the first GPU)
///   "all"       every device of the kind (GPU or not) the default choice has, so results do not
///               mix device types
///   "0,1" …     a comma list of selectors as --device takes (index, gpu, cpu, a name); a device
///               may appear more than once (each worker gets its own context)
/// Throws vb::Error for a selector that matches no device.
std::vector<DeviceInfo> sweep_devices(const std::string& spec);

/// The one device of an MPI rank: entry local_rank mod n of sweep_devices(spec), so the ranks on
/// one machine spread over its devices. "" reads as "all" unless $VOXBREAST_DEVICE is set.
DeviceInfo rank_device(const std::string& spec, int local_rank);

}  // namespace vb

#pragma once
/// Which OpenCL devices a sweep's workers drive (docs/SWEEP.md, "Devices").
#include <memory>
#include <string>
#include <vector>

#include "engine/sim/opencl_runtime.hpp"
#include "engine/study/mpi_world.hpp"

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

/// Opens this process's worker contexts for a batch (--devices spec): one per rank_device under
/// MPI, else every sweep_devices entry. Every rank throws the same vb::Error when any rank failed,
/// so no rank waits for one that has gone.
std::vector<std::unique_ptr<ClContext>> open_worker_contexts(const std::string& spec, const MpiWorld& world);

/// "index: name" of each context, as the sweep's worker names.
std::vector<std::string> worker_names(const std::vector<std::unique_ptr<ClContext>>& contexts);

}  // namespace vb

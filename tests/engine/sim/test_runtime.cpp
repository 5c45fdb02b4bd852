#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "engine/error.hpp"
#include "engine/sim/device_arena.hpp"
#include "engine/sim/device_memory.hpp"
#include "engine/sim/opencl_runtime.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

// The arena's arrays land at aligned offsets in one buffer, each sub-buffer sees its own array
// (copied or zero), and a write through a sub-buffer is what the whole buffer holds there.
TEST(DeviceArena, KeepsEachArrayAtItsOffsetAndSubBuffersViewThem) {
  const ClContext& cl = test::cl_context();
  DeviceArena arena;
  const std::vector<cl_int> ints = {1, -2, 3, -4, 5};
  const std::vector<cl_uchar> bytes(4097, 7);  // crosses a 4 KiB unit
  const std::size_t a = arena.add(ints.data(), ints.size() * sizeof(cl_int));
  const std::size_t b = arena.add(nullptr, 3 * sizeof(cl_float));
  const std::size_t c = arena.add(bytes.data(), bytes.size());
  arena.create(cl);
  EXPECT_EQ(arena.offset_units(a), 0u);
  EXPECT_EQ(arena.offset_units(b), 1u);
  EXPECT_EQ(arena.offset_units(c), 2u);
  EXPECT_EQ(arena.bytes(), 2 * DeviceArena::kUnit + bytes.size());

  std::vector<cl_int> read_ints(ints.size());
  cl.queue.enqueueReadBuffer(arena.part(a), CL_TRUE, 0, read_ints.size() * sizeof(cl_int), read_ints.data());
  EXPECT_EQ(read_ints, ints);
  std::vector<cl_float> zeros(3, 1.0f);
  cl.queue.enqueueReadBuffer(arena.part(b), CL_TRUE, 0, zeros.size() * sizeof(cl_float), zeros.data());
  EXPECT_EQ(zeros, std::vector<cl_float>(3, 0.0f));

  const std::vector<cl_float> written = {0.5f, -1.5f, 2.5f};
  cl.queue.enqueueWriteBuffer(arena.part(b), CL_TRUE, 0, written.size() * sizeof(cl_float), written.data());
  std::vector<unsigned char> whole(arena.bytes());
  cl.queue.enqueueReadBuffer(arena.buffer(), CL_TRUE, 0, whole.size(), whole.data());
  std::vector<cl_float> at_b(3);
  std::memcpy(at_b.data(), whole.data() + DeviceArena::kUnit, at_b.size() * sizeof(cl_float));
  EXPECT_EQ(at_b, written);
  EXPECT_EQ(whole[2 * DeviceArena::kUnit + 4096], 7);
  EXPECT_THROW(arena.add(nullptr, 4), Error);  // no arrays after create()
}

TEST(OpenCLRuntime, ListsAtLeastOneDevice) {
  const auto devices = list_devices();
  ASSERT_FALSE(devices.empty());
  for (const auto& d : devices) {
    EXPECT_FALSE(d.name.empty());
    EXPECT_GT(d.global_memory_bytes, 0u);
  }
}

TEST(OpenCLRuntime, SelectsByIndexAndRejectsUnknownSelectors) {
  EXPECT_EQ(select_device("0").index, 0);
  try {
    select_device("no-such-device-xyz");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("available"), std::string::npos) << e.what();
  }
}

TEST(OpenCLRuntime, FailedBuildReportsTheCompilerLog) {
  try {
    build_program(test::cl_context(), {"common.cl"}, "kernel void broken( { this is not C }\n", "-DVB_DOUBLE=0");
    FAIL() << "expected a build error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("kernel build failed"), std::string::npos) << msg;
    // The compiler's own diagnostics follow (their file naming and quoting vary by vendor; PoCL
    // and NVIDIA both say what they expected).
    EXPECT_NE(msg.find("error"), std::string::npos) << "message should carry the build log: " << msg;
    EXPECT_NE(msg.find("expected"), std::string::npos) << "message should carry the build log: " << msg;
  }
}

TEST(OpenCLRuntime, DoubleIsRefusedOnDeviceWithoutFp64) {
  DeviceInfo info = test::cl_context().info;
  info.fp64 = false;  // pretend: PoCL supports fp64, so emulate a device that does not
  const ClContext no_fp64(info);
  Scene s = test::box_scene(3, 3, 3, 0.002);
  s.solver.precision = Precision::Double;
  s.solver.dashpot_ratio = 0.1;
  const auto m = test::make_model(s);
  try {
    Simulator sim(s, m.lattice, m.elements, no_fp64);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("fp64"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("solver.precision"), std::string::npos) << e.what();
  }
}

TEST(OpenCLRuntime, ModelTooLargeForDeviceIsRefused) {
  DeviceInfo info = test::cl_context().info;
  info.global_memory_bytes = 1 << 16;  // 64 KiB "device"
  const ClContext tiny(info);
  Scene s = test::box_scene(20, 20, 20, 0.002);
  s.solver.dashpot_ratio = 0.1;
  const auto m = test::make_model(s);
  try {
    Simulator sim(s, m.lattice, m.elements, tiny);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("device memory"), std::string::npos) << e.what();
  }
}

// The lattice alone is enough to refuse a model far too large for the device (before its arrays
// are built), with the same message as the Simulator's; the hint's downsample is above the
// scene's own and suggests float only to a double run.
TEST(OpenCLRuntime, LatticeTooLargeForDeviceIsRefusedBeforeItsArrays) {
  DeviceInfo info = test::cl_context().info;
  info.global_memory_bytes = 1 << 18;  // 256 KiB "device"
  Scene s = test::box_scene(40, 40, 40, 0.002);
  s.model.downsample = 2;
  const Lattice lattice = test::make_model(s).lattice;  // 20³ elements: ~620 KB in float
  const auto message = [&](Precision p) {
    s.solver.precision = p;
    try {
      check_lattice_fits_device(s, lattice, info);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string in_float = message(Precision::Float);
  EXPECT_NE(in_float.find("of device memory"), std::string::npos) << in_float;
  EXPECT_NE(in_float.find("model.downsample to at least 3"), std::string::npos) << in_float;  // 620 KB·(2/3)³ fits
  EXPECT_EQ(in_float.find("float precision"), std::string::npos) << in_float;
  EXPECT_NE(message(Precision::Double).find("or use float precision"), std::string::npos);
  info.global_memory_bytes = std::uint64_t(1) << 30;
  EXPECT_EQ(message(Precision::Float), "no error");
}

// The state (u, v, the predicted stage, …) is one buffer (Simulator::state_): a device whose
// largest allocation is below it refuses the model by name, even with memory to spare.
TEST(OpenCLRuntime, StateLargerThanTheLargestAllocationIsRefused) {
  Scene s = test::box_scene(20, 20, 20, 0.002);
  s.solver.dashpot_ratio = 0.1;
  const auto m = test::make_model(s);
  const std::size_t state_bytes = 16 * m.lattice.element_count();  // one float4 per element
  DeviceInfo info = test::cl_context().info;
  info.max_allocation_bytes = 2 * state_bytes;  // room for any one array, not for u, v, ũ, ṽ together
  const ClContext small(info);
  try {
    Simulator sim(s, m.lattice, m.elements, small);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("state needs one buffer"), std::string::npos) << e.what();
  }
  info.max_allocation_bytes = 8 * state_bytes;
  EXPECT_NO_THROW(Simulator(s, m.lattice, m.elements, ClContext(info)));
}

TEST(OpenCLRuntime, DeviceMemoryEstimateScalesWithPrecisionAndLaw) {
  EXPECT_EQ(estimated_device_bytes(1000, 0, Precision::Float), 1000u * 72);
  EXPECT_EQ(estimated_device_bytes(1000, 10, Precision::Double), 1000u * 140 + 40);
  // hyperelastic: Q's 3 rows and C (4 float4) and a tissue id per element
  EXPECT_EQ(estimated_device_bytes(1000, 0, Precision::Float, true), 1000u * (72 + 65));
}

}  // namespace
}  // namespace vb

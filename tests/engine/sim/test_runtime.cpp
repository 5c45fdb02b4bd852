#include <gtest/gtest.h>

#include "engine/error.hpp"
#include "engine/sim/opencl_runtime.hpp"
#include "engine/sim/simulator.hpp"
#include "tests/engine/sim/sim_fixtures.hpp"

namespace vb {
namespace {

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

TEST(OpenCLRuntime, DeviceMemoryEstimateScalesWithPrecisionAndLaw) {
  EXPECT_EQ(estimated_device_bytes(1000, 0, Precision::Float), 1000u * 72);
  EXPECT_EQ(estimated_device_bytes(1000, 10, Precision::Double), 1000u * 140 + 40);
  EXPECT_EQ(estimated_device_bytes(1000, 0, Precision::Float, true), 1000u * (72 + 97));
}

}  // namespace
}  // namespace vb

// Output writers: result.h5 and summary.json round-trip, and atomic writing leaves no debris.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "io/hdf5_result.hpp"
#include "io/json_summary.hpp"
#include "voxbreast/config.hpp"

namespace fs = std::filesystem;

namespace vb {
namespace {

// ---- reading HDF5 back with the C API ------------------------------------------------------

class ReadFile {
 public:
  explicit ReadFile(const fs::path& path)
      : id_(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT)) {}
  ~ReadFile() {
    if (id_ >= 0) H5Fclose(id_);
  }
  ReadFile(const ReadFile&) = delete;
  ReadFile& operator=(const ReadFile&) = delete;
  hid_t id() const { return id_; }
  bool has(const char* path) const { return H5Lexists(id_, path, H5P_DEFAULT) > 0; }

  std::vector<hsize_t> shape(const char* dataset) const {
    const hid_t set = H5Dopen2(id_, dataset, H5P_DEFAULT);
    const hid_t space = H5Dget_space(set);
    std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)));
    H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    H5Sclose(space);
    H5Dclose(set);
    return dims;
  }

  /// Whole dataset converted to `memory_type` (HDF5 converts from the stored type).
  template <class T>
  std::vector<T> read(const char* dataset, hid_t memory_type) const {
    std::size_t count = 1;
    for (hsize_t d : shape(dataset)) count *= d;
    std::vector<T> values(count);
    const hid_t set = H5Dopen2(id_, dataset, H5P_DEFAULT);
    EXPECT_GE(H5Dread(set, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0)
        << dataset;
    H5Dclose(set);
    return values;
  }

  /// Stored type class and size of a dataset, to check what a reader gets without conversion.
  std::pair<H5T_class_t, std::size_t> stored_type(const char* dataset) const {
    const hid_t set = H5Dopen2(id_, dataset, H5P_DEFAULT);
    const hid_t type = H5Dget_type(set);
    const std::pair result{H5Tget_class(type), H5Tget_size(type)};
    H5Tclose(type);
    H5Dclose(set);
    return result;
  }

  template <class T>
  std::vector<T> attribute(const char* object, const char* name, hid_t memory_type) const {
    const hid_t attr = H5Aopen_by_name(id_, object, name, H5P_DEFAULT, H5P_DEFAULT);
    EXPECT_GE(attr, 0) << object << " @" << name;
    const hid_t space = H5Aget_space(attr);
    std::vector<T> values(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
    EXPECT_GE(H5Aread(attr, memory_type, values.data()), 0) << object << " @" << name;
    H5Sclose(space);
    H5Aclose(attr);
    return values;
  }

  std::vector<std::string> strings(const char* object, const char* name) const {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    H5Tset_cset(type, H5T_CSET_UTF8);  // HDF5 will not convert between character sets
    std::vector<char*> raw = attribute<char*>(object, name, type);
    std::vector<std::string> out;
    for (char* s : raw) {
      out.emplace_back(s ? s : "<null>");
      H5free_memory(s);
    }
    H5Tclose(type);
    return out;
  }

 private:
  hid_t id_;
};

// ---- a tiny run: 2×1×1 voxels, two elements of different tissues --------------------------

Lattice tiny_lattice() {
  Lattice l;
  l.dims = {2, 1, 1};
  l.spacing_m = 0.002;
  l.origin_m = {0.1, -0.2, 0.3};
  l.voxel_of_element = {0, 1};
  l.element_of_voxel = {0, 1};
  l.tissue_of_element = {0, 1};
  l.tissue_names = {"adipose", "glandular"};
  l.connection_count = 1;
  return l;
}

Scene tiny_scene() {
  Scene s;
  s.source_path = "scenes/tiny.toml";
  s.source_text = "[model]\nspacing = 0.002\n# ünïcode survives\n";
  s.materials["adipose"] = {"adipose", "linear", 3000.0, 950.0, false, 3};
  s.materials["glandular"] = {"glandular", "neo-hookean", 9000.0, 1040.0, false, 7};
  return s;
}

FinalState tiny_state() {
  FinalState s;
  s.displacement_m = {0.001, 0.0, -0.002, 0.0005, 0.0, -0.003};
  s.position_m = {0.101, -0.2, 0.298, 0.1025, -0.2, 0.297};
  s.velocity_m_s = {1e-5, 0, 0, 0, 2e-5, 0};
  s.volumetric_strain = {-0.01, 0.02};
  s.equivalent_strain = {0.05, 0.06};
  s.von_mises_stress_pa = {150.0, 540.0};
  return s;
}

Frames tiny_frames() {
  Frames f;
  f.time_s = {0.5, 1.0};
  f.displacement_m = {{1, 2, 3, 4, 5, 6}, {7, 8, 9, 10, 11, 12}};
  return f;
}

RunSummary tiny_summary() {
  RunSummary s;
  s.elements = 2;
  s.connections = 1;
  s.fixed_elements = 1;
  s.steps = 1234;
  s.dt_s = 1e-4;
  s.dt_auto = true;
  s.simulated_time_s = 0.1234;
  s.wall_time_s = 2.5;
  s.steps_per_second = 493.6;
  s.converged = true;
  s.stop_reason = "equilibrium";
  s.final_residual = 5e-7;
  s.final_speed_ratio = 1e-4;
  s.max_displacement_m = 0.003;
  s.volume_change = -0.002;
  s.device_name = "pthread-cpu";
  s.precision = "double";
  s.integrator = "heun";
  TrackedPointResult apex;
  apex.name = "apex";
  apex.point_m = {0.1, -0.2, 0.3};
  apex.rest_m = {0.1, -0.2, 0.3};
  apex.displacement_m = {0.0, 0.003, -0.004};
  apex.element = 0;
  s.tracked = {apex};
  IndenterResult indenter;
  indenter.position_m = {0.0, 0.0, 0.31};
  indenter.reaction_force_n = {0.0, 0.0, 0.5};
  indenter.contact_elements = 2;
  s.indenters = {indenter};
  return s;
}

class Writers : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("voxbreast-test-writers-" + std::to_string(::getpid()) + "-" + test->name());
    fs::remove_all(dir_);
    ensure_output_dir(dir_.string());
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }

  fs::path write_h5(const FinalState& state, const Frames& frames = tiny_frames()) const {
    const fs::path path = dir_ / "result.h5";
    write_result_h5(path.string(), lattice_, scene_, state, frames, summary_);
    return path;
  }

  fs::path dir_;
  Lattice lattice_ = tiny_lattice();
  Scene scene_ = tiny_scene();
  RunSummary summary_ = tiny_summary();
};

// ---- result.h5 -----------------------------------------------------------------------------

TEST_F(Writers, Hdf5ModelRoundTrips) {
  const ReadFile file(write_h5(tiny_state()));
  ASSERT_GE(file.id(), 0);

  EXPECT_EQ(file.shape("/model/rest_position_m"), (std::vector<hsize_t>{2, 3}));
  const auto rest = file.read<double>("/model/rest_position_m", H5T_NATIVE_DOUBLE);
  const std::vector<double> expected_rest{0.1, -0.2, 0.3, 0.102, -0.2, 0.3};
  for (std::size_t i = 0; i < rest.size(); ++i) EXPECT_DOUBLE_EQ(rest[i], expected_rest[i]) << i;

  EXPECT_EQ(file.shape("/model/voxel_ijk"), (std::vector<hsize_t>{2, 3}));
  EXPECT_EQ(file.stored_type("/model/voxel_ijk"), std::make_pair(H5T_INTEGER, std::size_t{4}));
  EXPECT_EQ(file.read<std::int32_t>("/model/voxel_ijk", H5T_NATIVE_INT32),
            (std::vector<std::int32_t>{0, 0, 0, 1, 0, 0}));

  EXPECT_EQ(file.shape("/model/tissue"), (std::vector<hsize_t>{2}));
  EXPECT_EQ(file.stored_type("/model/tissue"), std::make_pair(H5T_INTEGER, std::size_t{1}));
  EXPECT_EQ(file.read<std::uint8_t>("/model/tissue", H5T_NATIVE_UINT8),
            (std::vector<std::uint8_t>{0, 1}));
  EXPECT_EQ(file.strings("/model/tissue", "names"),
            (std::vector<std::string>{"adipose", "glandular"}));

  EXPECT_EQ(file.shape("/model/affine_voxel_to_world_m"), (std::vector<hsize_t>{4, 4}));
  const auto affine = file.read<double>("/model/affine_voxel_to_world_m", H5T_NATIVE_DOUBLE);
  const std::vector<double> expected_affine{0.002, 0, 0,     0.1, 0, 0.002, 0, -0.2,
                                            0,     0, 0.002, 0.3, 0, 0,     0, 1};
  EXPECT_EQ(affine, expected_affine);

  EXPECT_EQ(file.attribute<double>("/model", "spacing_m", H5T_NATIVE_DOUBLE),
            (std::vector<double>{0.002}));
  EXPECT_EQ(file.attribute<std::int32_t>("/model", "dims", H5T_NATIVE_INT32),
            (std::vector<std::int32_t>{2, 1, 1}));

  EXPECT_EQ(file.strings("/model/materials/glandular", "law"),
            (std::vector<std::string>{"neo-hookean"}));
  EXPECT_EQ(file.attribute<double>("/model/materials/glandular", "youngs_modulus_pa",
                                   H5T_NATIVE_DOUBLE),
            (std::vector<double>{9000.0}));
  EXPECT_EQ(file.attribute<double>("/model/materials/adipose", "density_kg_m3",
                                   H5T_NATIVE_DOUBLE),
            (std::vector<double>{950.0}));
}

TEST_F(Writers, Hdf5ModelOfARotatedLatticeIsInTheWorldFrame) {
  lattice_.rotation << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // lattice x axis along world y (oblique CT)
  const ReadFile file(write_h5(tiny_state()));
  const auto rest = file.read<double>("/model/rest_position_m", H5T_NATIVE_DOUBLE);
  EXPECT_NEAR(rest[3], 0.1, 1e-15);    // the second element is one voxel along world +y
  EXPECT_NEAR(rest[4], -0.198, 1e-15);
  const auto affine = file.read<double>("/model/affine_voxel_to_world_m", H5T_NATIVE_DOUBLE);
  EXPECT_DOUBLE_EQ(affine[4], 0.002);  // row y, column i
  EXPECT_DOUBLE_EQ(affine[0], 0.0);
}

TEST_F(Writers, Hdf5StateAndFramesRoundTrip) {
  const FinalState state = tiny_state();
  const ReadFile file(write_h5(state));
  ASSERT_GE(file.id(), 0);

  const std::vector<std::pair<const char*, const std::vector<double>*>> datasets{
      {"/state/position_m", &state.position_m},
      {"/state/displacement_m", &state.displacement_m},
      {"/state/velocity_m_s", &state.velocity_m_s},
      {"/state/volumetric_strain", &state.volumetric_strain},
      {"/state/equivalent_strain", &state.equivalent_strain},
      {"/state/von_mises_stress_pa", &state.von_mises_stress_pa}};
  for (const auto& [name, values] : datasets) {
    const std::vector<hsize_t> shape =
        values->size() == 6 ? std::vector<hsize_t>{2, 3} : std::vector<hsize_t>{2};
    EXPECT_EQ(file.shape(name), shape) << name;
    EXPECT_EQ(file.stored_type(name), std::make_pair(H5T_FLOAT, std::size_t{8})) << name;
    EXPECT_EQ(file.read<double>(name, H5T_NATIVE_DOUBLE), *values) << name;
  }

  EXPECT_EQ(file.read<double>("/frames/time_s", H5T_NATIVE_DOUBLE),
            (std::vector<double>{0.5, 1.0}));
  EXPECT_EQ(file.shape("/frames/displacement_m"), (std::vector<hsize_t>{2, 2, 3}));
  EXPECT_EQ(file.stored_type("/frames/displacement_m"),
            std::make_pair(H5T_FLOAT, std::size_t{4}));
  EXPECT_EQ(file.read<float>("/frames/displacement_m", H5T_NATIVE_FLOAT),
            (std::vector<float>{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12}));
}

TEST_F(Writers, Hdf5RootAttributesRoundTrip) {
  const ReadFile file(write_h5(tiny_state()));
  ASSERT_GE(file.id(), 0);
  EXPECT_EQ(file.strings("/", "scene_toml"), (std::vector<std::string>{scene_.source_text}));
  EXPECT_EQ(file.strings("/", "voxbreast_version"),
            (std::vector<std::string>{config::version}));
  EXPECT_EQ(file.strings("/", "git_commit"), (std::vector<std::string>{config::git_commit}));
  EXPECT_EQ(file.strings("/", "coordinate_frame"),
            (std::vector<std::string>{"DICOM LPS patient coordinates, metres"}));
  EXPECT_EQ(file.attribute<std::int64_t>("/", "steps", H5T_NATIVE_INT64),
            (std::vector<std::int64_t>{1234}));
  EXPECT_EQ(file.attribute<double>("/", "simulated_time_s", H5T_NATIVE_DOUBLE),
            (std::vector<double>{0.1234}));
  EXPECT_EQ(file.attribute<std::int32_t>("/", "converged", H5T_NATIVE_INT32),
            (std::vector<std::int32_t>{1}));
}

TEST_F(Writers, Hdf5WithoutFramesHasNoFramesGroup) {
  const ReadFile file(write_h5(tiny_state(), Frames{}));
  ASSERT_GE(file.id(), 0);
  EXPECT_TRUE(file.has("/state"));
  EXPECT_FALSE(file.has("/frames"));
}

TEST_F(Writers, Hdf5LargeSceneTextFitsInAnAttribute) {
  scene_.source_text = std::string(200000, '#');  // beyond the 64 KiB compact-attribute limit
  const ReadFile file(write_h5(tiny_state()));
  ASSERT_GE(file.id(), 0);
  EXPECT_EQ(file.strings("/", "scene_toml").at(0).size(), 200000u);
}

TEST_F(Writers, Hdf5OverwritesAnEarlierResult) {
  write_h5(tiny_state());
  summary_.steps = 99;
  const ReadFile file(write_h5(tiny_state()));
  EXPECT_EQ(file.attribute<std::int64_t>("/", "steps", H5T_NATIVE_INT64),
            (std::vector<std::int64_t>{99}));
  EXPECT_EQ(entries(), (std::vector<std::string>{"result.h5"}));
}

TEST_F(Writers, Hdf5WrongStateSizeNamesTheDatasetAndLeavesNoFile) {
  FinalState state = tiny_state();
  state.velocity_m_s.pop_back();
  try {
    write_h5(state);
    FAIL() << "expected vb::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/state/velocity_m_s"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(entries().empty());
}

TEST_F(Writers, Hdf5WrongFrameSizeThrows) {
  Frames frames = tiny_frames();
  frames.displacement_m[1].resize(3);
  EXPECT_THROW(write_h5(tiny_state(), frames), Error);
  EXPECT_TRUE(entries().empty());
}

// ---- summary.json --------------------------------------------------------------------------

TEST_F(Writers, JsonSummaryRoundTrips) {
  const fs::path path = dir_ / "summary.json";
  write_summary_json(path.string(), summary_, scene_);
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in);

  EXPECT_EQ(j["version"], config::version);
  EXPECT_EQ(j["git_commit"], config::git_commit);
  EXPECT_EQ(j["scene"], "scenes/tiny.toml");
  EXPECT_EQ(j["elements"], 2);
  EXPECT_EQ(j["connections"], 1);
  EXPECT_EQ(j["fixed_elements"], 1);
  EXPECT_EQ(j["steps"], 1234);
  EXPECT_DOUBLE_EQ(j["dt_s"].get<double>(), 1e-4);
  EXPECT_EQ(j["dt_auto"], true);
  EXPECT_DOUBLE_EQ(j["simulated_time_s"].get<double>(), 0.1234);
  EXPECT_DOUBLE_EQ(j["wall_time_s"].get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(j["steps_per_second"].get<double>(), 493.6);
  EXPECT_EQ(j["converged"], true);
  EXPECT_EQ(j["stop_reason"], "equilibrium");
  EXPECT_DOUBLE_EQ(j["final_residual"].get<double>(), 5e-7);
  EXPECT_DOUBLE_EQ(j["final_speed_ratio"].get<double>(), 1e-4);
  EXPECT_DOUBLE_EQ(j["max_displacement_m"].get<double>(), 0.003);
  EXPECT_DOUBLE_EQ(j["volume_change_fraction"].get<double>(), -0.002);
  EXPECT_EQ(j["device"]["name"], "pthread-cpu");
  EXPECT_EQ(j["device"]["precision"], "double");
  EXPECT_EQ(j["integrator"], "heun");

  const auto& apex = j["tracked"]["apex"];
  EXPECT_EQ(apex["point_m"], nlohmann::json({0.1, -0.2, 0.3}));
  EXPECT_EQ(apex["rest_position_m"], nlohmann::json({0.1, -0.2, 0.3}));
  EXPECT_EQ(apex["displacement_m"], nlohmann::json({0.0, 0.003, -0.004}));
  EXPECT_DOUBLE_EQ(apex["displacement_norm_m"].get<double>(), 0.005);
  EXPECT_EQ(apex["element"], 0);

  ASSERT_EQ(j["indenters"].size(), 1u);
  const auto& indenter = j["indenters"][0];
  EXPECT_EQ(indenter["position_m"], nlohmann::json({0.0, 0.0, 0.31}));
  EXPECT_EQ(indenter["reaction_force_n"], nlohmann::json({0.0, 0.0, 0.5}));
  EXPECT_DOUBLE_EQ(indenter["reaction_force_norm_n"].get<double>(), 0.5);
  EXPECT_EQ(indenter["contact_elements"], 2);
}

TEST_F(Writers, JsonNonFiniteNumbersBecomeNull) {
  summary_.final_residual = std::numeric_limits<double>::quiet_NaN();
  summary_.max_displacement_m = std::numeric_limits<double>::infinity();
  summary_.tracked[0].displacement_m.x() = std::numeric_limits<double>::quiet_NaN();
  const nlohmann::json in_memory = summary_to_json(summary_, scene_);
  EXPECT_TRUE(in_memory["final_residual"].is_null());
  EXPECT_TRUE(in_memory["max_displacement_m"].is_null());
  EXPECT_TRUE(in_memory["tracked"]["apex"]["displacement_m"][0].is_null());
  EXPECT_TRUE(in_memory["tracked"]["apex"]["displacement_norm_m"].is_null());

  const fs::path path = dir_ / "summary.json";
  write_summary_json(path.string(), summary_, scene_);
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in);  // strict parser: NaN would not parse
  EXPECT_TRUE(j["final_residual"].is_null());
  EXPECT_DOUBLE_EQ(j["wall_time_s"].get<double>(), 2.5);
}

TEST_F(Writers, EmptyTrackedAndIndentersAreEmptyContainers) {
  summary_.tracked.clear();
  summary_.indenters.clear();
  const nlohmann::json j = summary_to_json(summary_, scene_);
  EXPECT_TRUE(j["tracked"].is_object() && j["tracked"].empty());
  EXPECT_TRUE(j["indenters"].is_array() && j["indenters"].empty());
}

// ---- atomic writing ------------------------------------------------------------------------

TEST_F(Writers, BothWritersLeaveNoTemporaryFiles) {
  write_result_h5((dir_ / "result.h5").string(), lattice_, scene_, tiny_state(), tiny_frames(),
                  summary_);
  write_summary_json((dir_ / "summary.json").string(), summary_, scene_);
  EXPECT_EQ(entries(), (std::vector<std::string>{"result.h5", "summary.json"}));
}

TEST_F(Writers, UnwritableFolderThrowsAndLeavesNothing) {
  const std::string dir = "/proc/voxbreast-test/x";
  try {
    ensure_output_dir(dir);
    FAIL() << "expected vb::Error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("cannot write to output folder '" + dir + "': ", 0), 0u)
        << e.what();
  }
  EXPECT_THROW(write_result_h5(dir + "/result.h5", lattice_, scene_, tiny_state(), tiny_frames(),
                               summary_),
               Error);
  EXPECT_THROW(write_summary_json(dir + "/summary.json", summary_, scene_), Error);
  EXPECT_THROW(write_text_atomically(dir + "/notes.txt", "text"), Error);
  EXPECT_FALSE(fs::exists(dir));
}

TEST_F(Writers, OutputFolderThatIsAFileIsRejected) {
  const fs::path file = dir_ / "not-a-folder";
  write_text_atomically(file.string(), "x");
  EXPECT_THROW(ensure_output_dir(file.string()), Error);
  EXPECT_THROW(ensure_output_dir((file / "sub").string()), Error);
}

TEST_F(Writers, EnsureOutputDirCreatesParentsAndLeavesNoProbe) {
  const fs::path nested = dir_ / "a" / "b";
  ensure_output_dir(nested.string());
  EXPECT_TRUE(fs::is_directory(nested));
  EXPECT_TRUE(fs::is_empty(nested));
  ensure_output_dir(nested.string());  // existing folder is fine
}

TEST_F(Writers, OutputDirRemovesTheEmptyFoldersItCreated) {
  const fs::path nested = dir_ / "new" / "run";
  { const OutputDir out(nested.string()); EXPECT_TRUE(fs::is_directory(nested)); }
  EXPECT_FALSE(fs::exists(dir_ / "new"));  // both created, both empty: both gone
  EXPECT_TRUE(fs::is_directory(dir_));     // existed before: kept

  {
    const OutputDir out(nested.string());
    write_text_atomically((nested / "summary.json").string(), "{}");
  }
  EXPECT_TRUE(fs::exists(nested / "summary.json"));  // written: kept

  const fs::path sibling = dir_ / "new" / "other";
  { const OutputDir out(sibling.string()); }
  EXPECT_FALSE(fs::exists(sibling));
  EXPECT_TRUE(fs::is_directory(dir_ / "new"));  // existed before this one (it holds "run"): kept
}

TEST_F(Writers, TempPathIsHiddenAndUniqueInTheSameFolder) {
  const std::string final_path = (dir_ / "result.h5").string();
  const AtomicOutput a(final_path), b(final_path);
  EXPECT_EQ(fs::path(a.temp_path()).parent_path(), dir_);
  EXPECT_EQ(fs::path(a.temp_path()).filename().string().rfind(".result.h5.tmp-", 0), 0u);
  EXPECT_NE(a.temp_path(), b.temp_path());
  EXPECT_EQ(a.final_path(), final_path);
}

TEST_F(Writers, UncommittedTempFileIsRemoved) {
  std::string temp;
  {
    AtomicOutput out((dir_ / "result.h5").string());
    temp = out.temp_path();
    std::ofstream(temp) << "partial";
    ASSERT_TRUE(fs::exists(temp));
  }
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_TRUE(entries().empty());
}

TEST_F(Writers, CommitReplacesTheFinalFile) {
  const fs::path final_path = dir_ / "notes.txt";
  write_text_atomically(final_path.string(), "old");
  write_text_atomically(final_path.string(), "new");
  std::ifstream in(final_path);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "new");
  EXPECT_EQ(entries(), (std::vector<std::string>{"notes.txt"}));
}

TEST_F(Writers, CommitWithoutTempFileThrowsNamingBothPaths) {
  AtomicOutput out((dir_ / "result.h5").string());
  try {
    out.commit();
    FAIL() << "expected vb::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(out.temp_path()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(out.final_path()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vb

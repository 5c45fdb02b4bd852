#include "io/hdf5_result.hpp"

#include <hdf5.h>

#include <array>
#include <cctype>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "voxbreast/config.hpp"

namespace vb {
namespace {

// ---- errors --------------------------------------------------------------------------------

/// One line from HDF5's error stack: the operating system's reason when an entry carries one
/// (HDF5 writes it as "error message = '...'", e.g. no space left on device), else the most
/// specific entry. Clears the stack.
std::string hdf5_reason() {
  struct Found {
    std::string innermost, system;
  } found;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned n, const H5E_error2_t* err, void* out) -> herr_t {
        auto& f = *static_cast<Found*>(out);
        if (!err->desc) return 0;
        const std::string desc = err->desc;
        if (n == 0) f.innermost = desc;
        const std::string key = "error message = '";
        const std::size_t at = desc.find(key);
        if (at != std::string::npos && f.system.empty()) {
          const std::size_t from = at + key.size(), to = desc.find('\'', from);
          f.system = desc.substr(from, to == std::string::npos ? std::string::npos : to - from);
          if (!f.system.empty()) f.system[0] = char(std::tolower(static_cast<unsigned char>(f.system[0])));
        }
        return 0;
      },
      &found);
  H5Eclear2(H5E_DEFAULT);
  const std::string& reason = found.system.empty() ? found.innermost : found.system;
  return reason.substr(0, reason.find('\n'));
}

[[noreturn]] void fail(const std::string& what) {
  const std::string reason = hdf5_reason();
  throw Error(reason.empty() ? what : what + ": " + reason);
}

hid_t check_id(hid_t id, const std::string& what) {
  if (id < 0) fail(what);
  return id;
}

void check_status(herr_t status, const std::string& what) {
  if (status < 0) fail(what);
}

// ---- handles -------------------------------------------------------------------------------

/// Owns one HDF5 identifier; Close is the H5?close function matching how it was opened.
template <herr_t (*Close)(hid_t)>
class Handle {
 public:
  Handle(hid_t id, const std::string& what) : id_(check_id(id, what)) {}
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, H5I_INVALID_HID)) {}
  Handle& operator=(Handle&&) = delete;
  ~Handle() {
    if (id_ >= 0) Close(id_);  // error path only; close() reports failures
  }
  operator hid_t() const { return id_; }

  /// Closing a file flushes it, which can fail (disk full): close explicitly and check.
  void close(const std::string& what) {
    check_status(Close(std::exchange(id_, H5I_INVALID_HID)), what);
  }

 private:
  hid_t id_;
};

using FileHandle = Handle<H5Fclose>;
using SpaceHandle = Handle<H5Sclose>;
using TypeHandle = Handle<H5Tclose>;
using AttributeHandle = Handle<H5Aclose>;

/// An open group or dataset (H5Oclose closes either) and its path, for error messages.
struct Object {
  Handle<H5Oclose> handle;
  std::string path;

  std::string child(const std::string& name) const {
    return (path == "/" ? "" : path) + "/" + name;
  }
};

// ---- types and shapes ----------------------------------------------------------------------

/// Memory type and (explicitly little-endian, portable) file type for each stored C++ type.
template <class T>
struct H5Type;
template <>
struct H5Type<double> {
  static hid_t memory() { return H5T_NATIVE_DOUBLE; }
  static hid_t file() { return H5T_IEEE_F64LE; }
};
template <>
struct H5Type<float> {
  static hid_t memory() { return H5T_NATIVE_FLOAT; }
  static hid_t file() { return H5T_IEEE_F32LE; }
};
template <>
struct H5Type<std::int32_t> {
  static hid_t memory() { return H5T_NATIVE_INT32; }
  static hid_t file() { return H5T_STD_I32LE; }
};
template <>
struct H5Type<std::int64_t> {
  static hid_t memory() { return H5T_NATIVE_INT64; }
  static hid_t file() { return H5T_STD_I64LE; }
};
template <>
struct H5Type<std::uint8_t> {
  static hid_t memory() { return H5T_NATIVE_UINT8; }
  static hid_t file() { return H5T_STD_U8LE; }
};

template <class T>
concept Storable = requires { H5Type<T>::file(); };

using Shape = std::vector<hsize_t>;  ///< empty: scalar

std::size_t value_count(const Shape& shape) {
  std::size_t count = 1;
  for (hsize_t d : shape) count *= d;
  return count;
}

SpaceHandle make_space(const Shape& shape, const std::string& what) {
  if (shape.empty()) return SpaceHandle(H5Screate(H5S_SCALAR), what);
  return SpaceHandle(H5Screate_simple(static_cast<int>(shape.size()), shape.data(), nullptr), what);
}

/// Variable-length UTF-8 strings: h5py reads them as `str`, and the text lives in the global
/// heap, so a long scene file does not hit the 64 KiB limit on compact attributes.
TypeHandle string_type(const std::string& what) {
  TypeHandle type(H5Tcopy(H5T_C_S1), what);
  check_status(H5Tset_size(type, H5T_VARIABLE), what);
  check_status(H5Tset_cset(type, H5T_CSET_UTF8), what);
  return type;
}

// ---- groups, datasets, attributes ----------------------------------------------------------

Object open_root(hid_t file) {
  return {Handle<H5Oclose>(H5Gopen2(file, "/", H5P_DEFAULT), "cannot open group /"), "/"};
}

Object create_group(const Object& parent, const std::string& name) {
  const std::string path = parent.child(name);
  const hid_t id =
      H5Gcreate2(parent.handle, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  return {Handle<H5Oclose>(id, "cannot create group " + path), path};
}

Object create_dataset(const Object& parent, const std::string& name, hid_t file_type,
                      const Shape& shape) {
  const std::string path = parent.child(name);
  const std::string what = "cannot create dataset " + path;
  const SpaceHandle space = make_space(shape, what);
  const hid_t id = H5Dcreate2(parent.handle, name.c_str(), file_type, space, H5P_DEFAULT,
                              H5P_DEFAULT, H5P_DEFAULT);
  return {Handle<H5Oclose>(id, what), path};
}

/// Creates dataset `name` of shape `shape` under `parent` and writes `values` (row-major).
template <Storable T>
Object write_dataset(const Object& parent, const std::string& name, const std::vector<T>& values,
                     const Shape& shape) {
  Object set = create_dataset(parent, name, H5Type<T>::file(), shape);
  require(values.size() == value_count(shape),
          "has " + std::to_string(values.size()) + " values, expected " +
              std::to_string(value_count(shape)),
          set.path);
  if (!values.empty())  // HDF5 rejects a null buffer even for an empty write
    check_status(H5Dwrite(set.handle, H5Type<T>::memory(), H5S_ALL, H5S_ALL, H5P_DEFAULT,
                          values.data()),
                 "cannot write dataset " + set.path);
  return set;
}

void write_attribute_data(const Object& object, const std::string& name, hid_t file_type,
                          hid_t memory_type, const Shape& shape, const void* data) {
  const std::string what = "cannot write attribute '" + name + "' of " + object.path;
  const SpaceHandle space = make_space(shape, what);
  const AttributeHandle attribute(
      H5Acreate2(object.handle, name.c_str(), file_type, space, H5P_DEFAULT, H5P_DEFAULT), what);
  if (value_count(shape) > 0)  // HDF5 rejects a null buffer even for an empty write
    check_status(H5Awrite(attribute, memory_type, data), what);
}

template <Storable T>
void write_attribute(const Object& object, const std::string& name, T value) {
  write_attribute_data(object, name, H5Type<T>::file(), H5Type<T>::memory(), {}, &value);
}

template <Storable T, std::size_t N>
void write_attribute(const Object& object, const std::string& name, const std::array<T, N>& v) {
  write_attribute_data(object, name, H5Type<T>::file(), H5Type<T>::memory(), {N}, v.data());
}

void write_attribute(const Object& object, const std::string& name, const std::string& value) {
  const TypeHandle type = string_type("cannot make string type for " + name);
  const char* text = value.c_str();
  write_attribute_data(object, name, type, type, {}, &text);
}

void write_attribute(const Object& object, const std::string& name,
                     const std::vector<std::string>& values) {
  const TypeHandle type = string_type("cannot make string type for " + name);
  std::vector<const char*> texts;
  for (const auto& v : values) texts.push_back(v.c_str());
  write_attribute_data(object, name, type, type, {values.size()}, texts.data());
}

/// Once, before HDF5's first use: no error dumps on stderr (errors become one-line vb::Errors), and
/// no library shutdown at exit, which closes what a failed write left open again and crashed in
/// it after a full disk (the temporary file is removed by then; the OS frees the rest).
void prepare_hdf5() {
  static const bool prepared = [] {
    H5dont_atexit();
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)prepared;
}

// ---- the result file -----------------------------------------------------------------------

/// Per-element voxel indices (n×3) and rest positions (n×3, m, world frame).
struct ElementGeometry {
  std::vector<std::int32_t> voxel_ijk;
  std::vector<double> rest_position_m;
};

ElementGeometry element_geometry(const Lattice& lattice) {
  ElementGeometry g;
  g.voxel_ijk.reserve(3 * lattice.element_count());
  g.rest_position_m.reserve(3 * lattice.element_count());
  for (std::size_t e = 0; e < lattice.element_count(); ++e) {
    const auto ijk = lattice.voxel_ijk(e);
    const Eigen::Vector3d x = lattice.rest_position(e);  // includes the lattice's rotation
    for (int a = 0; a < 3; ++a) {
      g.voxel_ijk.push_back(ijk[a]);
      g.rest_position_m.push_back(x[a]);
    }
  }
  return g;
}

/// Voxel index → world (m), 4×4 row-major (rotation × spacing, then the origin).
std::vector<double> affine_rows(const Lattice& lattice) {
  const Eigen::Matrix4d a = lattice.affine();
  std::vector<double> rows;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) rows.push_back(a(r, c));
  return rows;
}

void write_materials(const Object& model, const std::map<std::string, MaterialSpec>& materials) {
  const Object group = create_group(model, "materials");
  for (const auto& [name, material] : materials) {
    const Object m = create_group(group, name);
    write_attribute(m, "law", material.law);
    write_attribute(m, "youngs_modulus_pa", material.youngs_modulus_pa);
    write_attribute(m, "density_kg_m3", material.density_kg_m3);
  }
}

void write_model(const Object& root, const Lattice& lattice, const Scene& scene) {
  const hsize_t n = lattice.element_count();
  const Object model = create_group(root, "model");
  const ElementGeometry geometry = element_geometry(lattice);
  write_dataset(model, "rest_position_m", geometry.rest_position_m, {n, 3});
  write_dataset(model, "voxel_ijk", geometry.voxel_ijk, {n, 3});
  const Object tissue = write_dataset(model, "tissue", lattice.tissue_of_element, {n});
  write_attribute(tissue, "names", lattice.tissue_names);
  write_dataset(model, "affine_voxel_to_world_m", affine_rows(lattice), {4, 4});
  write_attribute(model, "spacing_m", lattice.spacing_m);
  write_attribute(model, "dims", std::array<std::int32_t, 3>{lattice.dims[0], lattice.dims[1],
                                                             lattice.dims[2]});
  write_materials(model, scene.materials);
}

void write_state(const Object& root, const FinalState& state, hsize_t n) {
  const Object group = create_group(root, "state");
  write_dataset(group, "position_m", state.position_m, {n, 3});
  write_dataset(group, "displacement_m", state.displacement_m, {n, 3});
  write_dataset(group, "velocity_m_s", state.velocity_m_s, {n, 3});
  write_dataset(group, "volumetric_strain", state.volumetric_strain, {n});
  write_dataset(group, "equivalent_strain", state.equivalent_strain, {n});
  write_dataset(group, "von_mises_stress_pa", state.von_mises_stress_pa, {n});
  if (!state.rest_offset_m.empty()) write_dataset(group, "rest_offset_m", state.rest_offset_m, {n, 3});
}

/// Frames are written one at a time into an (F, n, 3) dataset, so a long run's frames are
/// never copied into one contiguous buffer.
void write_frames(const Object& root, const Frames& frames, hsize_t n) {
  if (frames.time_s.empty() && frames.displacement_m.empty()) return;
  const hsize_t count = frames.displacement_m.size();
  const Object group = create_group(root, "frames");
  write_dataset(group, "time_s", frames.time_s, {count});
  const Object set = create_dataset(group, "displacement_m", H5Type<float>::file(), {count, n, 3});
  const std::string what = "cannot write dataset " + set.path;
  const SpaceHandle file_space(H5Dget_space(set.handle), what);
  const SpaceHandle frame_space = make_space({n, 3}, what);
  for (hsize_t f = 0; f < count; ++f) {
    const std::vector<float>& frame = frames.displacement_m[f];
    require(frame.size() == 3 * n,
            "frame " + std::to_string(f) + " has " + std::to_string(frame.size()) +
                " values, expected " + std::to_string(3 * n),
            set.path);
    if (n == 0) continue;  // HDF5 rejects a null buffer even for an empty write
    const std::array<hsize_t, 3> start{f, 0, 0}, size{1, n, 3};
    check_status(H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start.data(), nullptr,
                                     size.data(), nullptr),
                 what);
    check_status(H5Dwrite(set.handle, H5Type<float>::memory(), frame_space, file_space,
                          H5P_DEFAULT, frame.data()),
                 what);
  }
}

void write_run_attributes(const Object& root, const Scene& scene, const RunSummary& summary) {
  write_attribute(root, "scene_toml", scene.source_text);
  write_attribute(root, "voxbreast_version", std::string(config::version));
  write_attribute(root, "git_commit", std::string(config::git_commit));
  write_attribute(root, "coordinate_frame", std::string("DICOM LPS patient coordinates, metres"));
  write_attribute(root, "steps", std::int64_t{summary.steps});
  write_attribute(root, "simulated_time_s", summary.simulated_time_s);
  write_attribute(root, "converged", std::int32_t{summary.converged ? 1 : 0});
}

void write_contents(hid_t file, const Lattice& lattice, const Scene& scene,
                    const FinalState& state, const Frames& frames, const RunSummary& summary) {
  const Object root = open_root(file);
  write_run_attributes(root, scene, summary);
  write_model(root, lattice, scene);
  write_state(root, state, lattice.element_count());
  write_frames(root, frames, lattice.element_count());
}

}  // namespace

void write_result_h5(const std::string& path, const Lattice& lattice, const Scene& scene,
                     const FinalState& state, const Frames& frames, const RunSummary& summary) {
  prepare_hdf5();
  AtomicOutput out(path);
  try {
    // Closing the file closes whatever is still open in it, also after a failed write.
    Handle<H5Pclose> access(H5Pcreate(H5P_FILE_ACCESS), "cannot create file");
    check_status(H5Pset_fclose_degree(access, H5F_CLOSE_STRONG), "cannot create file");
    FileHandle file(H5Fcreate(out.temp_path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access),
                    "cannot create file");
    write_contents(file, lattice, scene, state, frames, summary);  // closes every object it opens
    file.close("cannot finish writing file");
  } catch (const Error& e) {
    throw Error(e.problem(), e.location().empty() ? path : path + ": " + e.location(), e.hint());
  }
  out.commit();
}

}  // namespace vb

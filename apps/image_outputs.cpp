#include "apps/image_outputs.hpp"

#include <malloc.h>
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include "engine/image/deformation_field.hpp"
#include "engine/image/displacement_stats.hpp"
#include "engine/image/source_slices.hpp"
#include "io/dicom_io.hpp"
#include "engine/image/structure_set.hpp"
#include "io/metaimage_io.hpp"
#include "io/nifti_io.hpp"
#include "io/rtstruct.hpp"
#include "io/scene_file.hpp"

namespace vb::app {
namespace {

std::vector<double> displacement_norm_mm(const FinalState& s) {
  std::vector<double> out(s.displacement_m.size() / 3);
  for (std::size_t e = 0; e < out.size(); ++e)
    out[e] = 1e3 * std::sqrt(s.displacement_m[3 * e] * s.displacement_m[3 * e] +
                             s.displacement_m[3 * e + 1] * s.displacement_m[3 * e + 1] +
                             s.displacement_m[3 * e + 2] * s.displacement_m[3 * e + 2]);
  return out;
}

/// A DVF as NIfTI (in the scene's layout) and as MetaImage; its statistics for summary.json.
void write_dvf(const std::string& dir, const std::string& name, const ImageVolume& grid, const std::vector<float>& u,
               const DvfFileOptions& files, nlohmann::json& written, const ImageProgress& progress) {
  write_nifti_displacement(dir + "/" + name + ".nii.gz", grid, u,
                           files.legacy_nifti ? NiftiDisplacementLayout::VectorLps : NiftiDisplacementLayout::DispVectRas,
                           [&](double f) { progress(0.5 * f); });
  write_metaimage_displacement(dir + "/" + name + ".mha", grid, u, [&](double f) { progress(0.5 + 0.5 * f); });
  written[name] = name + ".nii.gz";
  written[name + "_mha"] = name + ".mha";
  const DisplacementStats s = displacement_stats(u);
  written[name + "_stats_mm"] = {{"min", s.min_mm},           {"max", s.max_mm},
                                 {"mean", s.mean_mm},         {"mean_abs", s.mean_abs_mm},
                                 {"mean_length", s.mean_length_mm}, {"max_length", s.max_length_mm}};
}


/// A field of /proc/self/status in bytes ("VmHWM": peak resident memory, "VmRSS": now), or
/// nothing where there is no such file.
std::optional<double> process_memory_bytes(const std::string& field) {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind(field + ":", 0) == 0) {
      std::istringstream in(line.substr(field.size() + 1));
      double kib = 0;
      if (in >> kib) return 1024 * kib;
    }
  return std::nullopt;
}

/// User + system CPU seconds of the process so far, all threads.
double process_cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) + 1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

/// Starts the peak of resident memory afresh (Linux: "5" written to /proc/self/clear_refs).
void reset_peak_memory() { std::ofstream("/proc/self/clear_refs") << "5"; }

/// Shares out the progress of the image outputs over their steps, weighted by their cost, and
/// times each step (wall-clock seconds, summary.json `image_outputs.step_seconds`).
class Steps {
 public:
  using Clock = std::chrono::steady_clock;
  Steps(const ImageOutputProgress& progress, double total) : progress_(progress), total_(total) {}
  /// A step of `weight` starts (the one before ends); the returned callback reports its own fraction done.
  ImageProgress step(const std::string& what, double weight) {
    close();
    done_ += weight_;
    weight_ = weight;
    what_ = what;
    if (progress_) progress_(what, done_ / total_);
    return [this, what](double fraction) {
      if (progress_) progress_(what, (done_ + fraction * weight_) / total_);
    };
  }
  /// Ends the step under way; the seconds of every step so far.
  const nlohmann::json& seconds() {
    close();
    return seconds_;
  }
  /// The CPU seconds (all threads, user + system) of each step so far: on a shared machine the
  /// work a step takes, whatever share of the cores it got.
  const nlohmann::json& cpu_seconds() const { return cpu_seconds_; }
  /// The peak resident memory of each step so far (bytes, Linux).
  const nlohmann::json& peak_bytes() const { return peak_bytes_; }

 private:
  void close() {
    const Clock::time_point now = Clock::now();
    if (!what_.empty()) {
      seconds_[what_] = seconds_.value(what_, 0.0) + std::chrono::duration<double>(now - start_).count();
      const double cpu = process_cpu_seconds();
      cpu_seconds_[what_] = cpu_seconds_.value(what_, 0.0) + (cpu - cpu_start_);
      cpu_start_ = cpu;
      if (const std::optional<double> peak = process_memory_bytes("VmHWM"))
        peak_bytes_[what_] = std::max(peak_bytes_.value(what_, 0.0), *peak);
      overall_peak_ = std::max(overall_peak_, peak_bytes_.value(what_, 0.0));
      reset_peak_memory();  // the next step's peak starts afresh
    }
    what_.clear();
    start_ = now;
  }
  const ImageOutputProgress& progress_;
  double total_, done_ = 0, weight_ = 0;
  std::string what_;
  Clock::time_point start_ = Clock::now();
  nlohmann::json seconds_ = nlohmann::json::object(), cpu_seconds_ = nlohmann::json::object(),
                 peak_bytes_ = nlohmann::json::object();
  double cpu_start_ = process_cpu_seconds();
  double overall_peak_ = 0;

 public:
  /// The largest of the steps' peaks (0 where /proc is not there).
  double overall_peak() const { return overall_peak_; }
};

}  // namespace

nlohmann::json write_image_outputs(const std::string& dir, const Scene& scene, const PreparedModel& model,
                                   const FinalState& state, const ImageOutputProgress& progress) {
  const OutputSpec& want = scene.output;
  const Lattice& lattice = model.lattice;
  const ImageVolume& ct = *model.ct;
  const ImageVolume* labels = model.labels ? &*model.labels : nullptr;
  nlohmann::json written = nlohmann::json::object();
  // Image-sized buffers (megabytes) are mapped and unmapped on their own: glibc's default raises
  // its mmap threshold to 32 MiB after the first such buffer is freed, after which freed images
  // stay in the heap and count as resident, and the next step's buffers add to them.
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  const std::optional<double> memory_before = process_memory_bytes("VmRSS");
  reset_peak_memory();
  const LatticeField field(lattice, state.displacement_m);
  const DvfFileOptions files = dvf_file_options(scene);
  const bool warp = want.dvf || want.warped_ct || want.warped_ct_dicom;
  // Weights: rough shares of the time each step takes on a CPU (clinical-size CT, docs/BENCHMARKS.md).
  const bool structures = labels && want.warped_ct_dicom;
  Steps steps(progress, (want.dvf ? 4 : 0) + (warp ? 4 : 0) + (want.warped_ct ? 0.5 : 0) +
                            (want.warped_ct_dicom ? 1 : 0) + (labels && warp ? 1 : 0) + (want.fields ? 2 : 0));
  // Memory: besides the CT and its labels, at most the forward field (3 floats a voxel), or the
  // inverse field and the warped CT (3 + 1), or the inverse field and the warped labels (3 + 1)
  // are held at once; every file is written from them in blocks (about a MiB in flight). The
  // warped structures are contoured once the inverse field is gone.
  if (want.dvf) {
    const std::vector<float> u = forward_displacement_on_grid(field, ct, steps.step("forward DVF", 1));
    write_dvf(dir, "dvf", ct, u, files, written, steps.step("writing dvf.nii.gz and dvf.mha", 1));
  }
  if (warp) {
    WarpResult w = warp_image(ct, lattice, state.displacement_m, 30, steps.step("inverse DVF and warped CT", 4));
    if (want.dvf)
      write_dvf(dir, "dvf_inverse", ct, w.inverse_field, files, written,
                steps.step("writing dvf_inverse.nii.gz and dvf_inverse.mha", 2));
    if (want.warped_ct) {
      write_nifti(dir + "/warped_ct.nii.gz", w.warped, NiftiType::Int16, steps.step("writing warped_ct.nii.gz", 0.5));
      written["warped_ct"] = "warped_ct.nii.gz";
    }
    std::optional<WrittenDicomSeries> warped_series;
    if (want.warped_ct_dicom) {
      steps.step("warped CT series", 1);
      DicomSeriesOptions series;
      series.series_description = "VoxBreast warped CT";
      series.patient_position = dicom_patient_position(scene.gravity.active ? scene.gravity.acceleration_m_s2 : Vec3::Zero());
      if (!ct.dicom_tags.empty()) series.source_slices = source_slices_read(ct, w.inverse_field);
      // a rerun replaces its own earlier series
      warped_series = replace_dicom_series(dir + "/warped_ct_dicom", w.warped, series);
      written["warped_ct_dicom"] = "warped_ct_dicom/";
    }
    std::vector<float>().swap(w.warped.values);  // written: the warped labels take its place
    written["warp_vacated_voxels"] = w.vacated_voxels;
    written["warp_max_inversion_residual_m"] = w.max_fixed_point_residual_m;
    if (warped_series && files.dicom) {
      steps.step("registration object", 0);
      write_dicom_deformable_registration(dir + "/dvf_inverse.dcm", ct, w.inverse_field, ct, *warped_series);
      written["dvf_inverse_dicom"] = "dvf_inverse.dcm";
    }
    if (labels) {
      const ImageVolume warped_labels =
          warp_labels(*labels, lattice, state.displacement_m, w.inverse_field, 30, steps.step("warped labels", 1));
      std::vector<float>().swap(w.inverse_field);  // the labels were its last use
      write_nifti(dir + "/warped_labels.nii.gz", warped_labels, NiftiType::Int16);
      written["warped_labels"] = "warped_labels.nii.gz";
      if (structures) {
        write_rtstruct(dir + "/warped_structures.dcm", structures_of_labels(warped_labels, model.label_names),
                       dir + "/warped_ct_dicom", "VoxBreast warped");
        written["warped_structures"] = "warped_structures.dcm";
      }
    }
  }
  if (want.fields) {
    const ImageProgress report = steps.step("maps", 2);
    std::vector<double> tissue(lattice.element_count());
    for (std::size_t e = 0; e < tissue.size(); ++e) tissue[e] = lattice.tissue_of_element[e] + 1;
    const std::vector<std::pair<std::string, std::vector<double>>> maps = {
        {"model_labels.nii.gz", tissue},
        {"displacement_mm.nii.gz", displacement_norm_mm(state)},
        {"equivalent_strain.nii.gz", state.equivalent_strain},
        {"von_mises_stress_pa.nii.gz", state.von_mises_stress_pa}};
    for (std::size_t m = 0; m < maps.size(); ++m) {
      const double n = double(maps.size());
      write_nifti(dir + "/" + maps[m].first, rasterise_elements(field, ct, maps[m].second, 0.f),
                  m == 0 ? NiftiType::UInt8 : NiftiType::Float32, [&](double f) { report((double(m) + f) / n); });
    }
    nlohmann::json names = nlohmann::json::object();
    for (std::size_t t = 0; t < lattice.tissue_names.size(); ++t) names[std::to_string(t + 1)] = lattice.tissue_names[t];
    written["model_labels"] = {{"file", "model_labels.nii.gz"}, {"values", names}};
    written["fields"] = {"displacement_mm.nii.gz", "equivalent_strain.nii.gz", "von_mises_stress_pa.nii.gz"};
  }
  written["step_seconds"] = steps.seconds();
  written["step_cpu_seconds"] = steps.cpu_seconds();
  const std::optional<double> last = process_memory_bytes("VmHWM");
  const double peak = std::max(steps.overall_peak(), last.value_or(0.0));
  if (memory_before && peak > 0)
    written["host_memory"] = {{"before_bytes", *memory_before},
                              {"peak_bytes", peak},
                              {"step_peak_bytes", steps.peak_bytes()},
                              {"ct_float_bytes", double(4 * ct.voxel_count())}};
  return written;
}

}  // namespace vb::app

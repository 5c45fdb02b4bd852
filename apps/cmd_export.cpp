// voxbreast export SCENE.toml --feb model.feb — the scene's lattice as an FEBio model: the dual
// cells of the element centres as hexahedra, the tissues' laws, held elements as fixed nodes and
// gravity as a body load (docs/EXPORT.md).
//   voxbreast export data-samples/phantom/scene.toml --feb out/phantom.feb
#include <cstdio>
#include <filesystem>
#include <memory>

#include "apps/commands.hpp"
#include "apps/simulation_setup.hpp"
#include "engine/error.hpp"
#include "io/atomic_file.hpp"
#include "io/febio_file.hpp"

namespace vb::app {
namespace {

struct ExportOptions {
  std::string scene;
  std::string feb;
};

/// Scene parts the FEBio model does not carry, for a warning.
std::string left_out(const Scene& s) {
  std::string out;
  const auto add = [&](bool present, const char* what) {
    if (present) out += std::string(out.empty() ? "" : ", ") + what;
  };
  add(!s.indenters.empty(), "indenters");
  add(!s.tori.empty(), "device tori");
  add(s.volume.preserve, "the volume constraint");
  add(s.reference_state.active, "the unloaded reference state");
  add(s.reproducibility.active, "reproducibility runs");
  return out;
}

int run_export(const ExportOptions& o) {
  const Scene scene = load_scene(o.scene, "");
  const std::filesystem::path feb(o.feb);
  const OutputDir output_dir(feb.parent_path().empty() ? "." : feb.parent_path().string());
  const PreparedModel model = prepare_model(scene);
  const std::size_t n = model.lattice.element_count();
  std::vector<bool> held(n);
  for (std::size_t e = 0; e < n; ++e) {
    held[e] = model.elements.inverse_mass[e] == 0;
    for (int c = 0; c < 3; ++c)
      require(model.elements.displacement_m[3 * e + c] == 0,
              "a posed anchor moves held elements; the FEBio export holds them where they are", o.scene,
              "set the anchors' rpy_deg to zero to export");
  }
  const FebioExportSummary s = write_febio(o.feb, scene, model.lattice, held);
  std::printf("wrote %s: %zu nodes, %zu hex8 elements, %zu fixed nodes%s\n", o.feb.c_str(), s.nodes, s.hexahedra,
              s.fixed_nodes, scene.gravity.active ? ", gravity as a body load" : "");
  for (const std::string& w : model.warnings) std::fprintf(stderr, "voxbreast: warning: %s\n", w.c_str());
  if (s.elements_left_out)
    std::fprintf(stderr, "voxbreast: warning: %zu elements are in no complete dual cell (one-voxel strands) and are "
                 "not in the FEBio mesh\n", s.elements_left_out);
  for (const std::string& note : s.notes) std::fprintf(stderr, "voxbreast: note: %s\n", note.c_str());
  if (const std::string missing = left_out(scene); !missing.empty())
    std::fprintf(stderr, "voxbreast: warning: not exported: %s\n", missing.c_str());
  return 0;
}

}  // namespace

Command add_export(CLI::App& app) {
  auto o = std::make_shared<ExportOptions>();
  auto* sub = app.add_subcommand("export", "Write a scene's lattice as an FEBio model (.feb, spec 4.0)");
  sub->add_option("scene", o->scene, "scene file (TOML)")->required()->check(CLI::ExistingFile);
  sub->add_option("--feb", o->feb, "FEBio file to write")->required();
  return {sub, [o] { return run_export(*o); }};
}

}  // namespace vb::app

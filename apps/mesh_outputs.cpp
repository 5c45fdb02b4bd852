#include "apps/mesh_outputs.hpp"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "engine/surface/surface_mesh.hpp"
#include "io/atomic_file.hpp"
#include "io/lattice_vtu.hpp"
#include "io/surface_mesh_files.hpp"

namespace vb::app {

namespace {

/// The surface and the lattice at every stored frame, with .pvd collections that ParaView plays
/// as time series. Returns the .pvd files' names.
std::vector<std::string> write_frame_series(const std::string& dir, const SurfaceMesh& mesh, const Lattice& lattice,
                                            const Frames& frames) {
  std::filesystem::create_directories(dir + "/frames");
  std::ostringstream surface_pvd, lattice_pvd;
  const char* head = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  surface_pvd << head;
  lattice_pvd << head;
  for (std::size_t f = 0; f < frames.time_s.size(); ++f) {
    const std::vector<double> u(frames.displacement_m[f].begin(), frames.displacement_m[f].end());
    const std::vector<double> x = element_positions_m(lattice, u);
    char surface[40], volume[40];
    std::snprintf(surface, sizeof surface, "frames/surface_%04zu.vtp", f);
    std::snprintf(volume, sizeof volume, "frames/lattice_%04zu.vtu", f);
    write_surface_vtp(dir + "/" + surface, mesh, x, u);
    write_lattice_vtu(dir + "/" + volume, lattice, x, u);
    surface_pvd << "<DataSet timestep=\"" << frames.time_s[f] << "\" file=\"" << surface << "\"/>\n";
    lattice_pvd << "<DataSet timestep=\"" << frames.time_s[f] << "\" file=\"" << volume << "\"/>\n";
  }
  surface_pvd << "</Collection>\n</VTKFile>\n";
  lattice_pvd << "</Collection>\n</VTKFile>\n";
  write_text_atomically(dir + "/surface.pvd", surface_pvd.str());
  write_text_atomically(dir + "/lattice.pvd", lattice_pvd.str());
  return {"surface.pvd", "lattice.pvd"};
}

}  // namespace

nlohmann::json write_mesh_outputs(const std::string& dir, const Lattice& lattice, const FinalState& state,
                                  const Frames& frames) {
  const SurfaceMesh mesh = build_surface(lattice);
  const std::vector<double> rest = element_positions_m(lattice);
  const std::vector<ElementField> fields = {
      {"equivalent_strain", state.equivalent_strain, 1},
      {"von_mises_stress_pa", state.von_mises_stress_pa, 1},
      {"volumetric_strain", state.volumetric_strain, 1},
  };
  // Rest surface without results (the reference shape), deformed surface coloured by them.
  write_surface_vtp(dir + "/surface_rest.vtp", mesh, rest);
  write_surface_vtp(dir + "/surface.vtp", mesh, state.position_m, state.displacement_m, fields);
  write_surface_stl(dir + "/surface.stl", mesh, state.position_m);
  write_surface_ply(dir + "/surface.ply", mesh, state.position_m);
  write_lattice_vtu(dir + "/lattice.vtu", lattice, state.position_m, state.displacement_m, fields);
  nlohmann::json files = {"surface_rest.vtp", "surface.vtp", "surface.stl", "surface.ply", "lattice.vtu"};
  if (!state.rest_offset_m.empty()) {  // the estimated unloaded shape, offsets from the CT as data
    write_surface_vtp(dir + "/surface_unloaded.vtp", mesh, element_positions_m(lattice, state.rest_offset_m),
                      state.rest_offset_m);
    files.push_back("surface_unloaded.vtp");
  }
  if (!frames.time_s.empty())
    for (const std::string& pvd : write_frame_series(dir, mesh, lattice, frames)) files.push_back(pvd);
  return {{"files", files},
          {"frames", frames.time_s.size()},
          {"surface_vertices", mesh.element_of_vertex.size()},
          {"surface_triangles", mesh.triangles.size()}};
}

}  // namespace vb::app

#include "apps/device_mesh_outputs.hpp"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "engine/device/torus.hpp"
#include "io/atomic_file.hpp"
#include "io/triangle_mesh_files.hpp"

namespace vb::app {

nlohmann::json write_device_meshes(const std::string& dir, const Scene& scene, double t_s, const Frames& frames) {
  nlohmann::json files = nlohmann::json::array();
  for (const TorusSpec& torus : scene.tori) {
    const std::string base = "device_" + torus.name;
    const TriangleMesh mesh = torus_mesh(torus, t_s);
    write_triangle_mesh_vtp(dir + "/" + base + ".vtp", mesh);
    write_triangle_mesh_stl(dir + "/" + base + ".stl", mesh);
    files.push_back(base + ".vtp");
    files.push_back(base + ".stl");
    if (frames.time_s.empty()) continue;
    std::filesystem::create_directories(dir + "/frames");
    std::ostringstream pvd;
    pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
    for (std::size_t f = 0; f < frames.time_s.size(); ++f) {
      char name[160];
      std::snprintf(name, sizeof name, "frames/%s_%04zu.vtp", base.c_str(), f);
      write_triangle_mesh_vtp(dir + "/" + name, torus_mesh(torus, frames.time_s[f]));
      pvd << "<DataSet timestep=\"" << frames.time_s[f] << "\" file=\"" << name << "\"/>\n";
    }
    pvd << "</Collection>\n</VTKFile>\n";
    write_text_atomically(dir + "/" + base + ".pvd", pvd.str());
    files.push_back(base + ".pvd");
  }
  return files;
}

}  // namespace vb::app

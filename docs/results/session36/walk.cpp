// one-off: relaxation's host bounds, two walks (before) against one (this change), phantom model
#include <chrono>
#include <iostream>
#include "engine/image/image_lattice.hpp"
#include "engine/sim/time_step.hpp"
#include "io/nifti_io.hpp"
#include "io/scene_file.hpp"
using namespace vb;
int main() {
  const std::string dir = "/work/main/data-samples/phantom/";
  Scene scene = parse_scene_file(dir + "scene.toml");
  const ImageVolume ct = read_nifti(scene.model.image_path), labels = read_nifti(scene.model.labels_path);
  const Lattice lattice = build_lattice(lattice_volume_from_image(scene.model, ct, classify_image(scene.model, ct, &labels)), scene.model.downsample);
  const ElementArrays el = make_element_arrays(scene, lattice);
  scene.solver.integrator = Integrator::Relaxation;
  std::cout << lattice.element_count() << " elements\n";
  using C = std::chrono::steady_clock;
  double sink = 0;
  for (int round = 0; round < 5; ++round) {
    auto t0 = C::now();
    for (int i = 0; i < 10; ++i) {  // before: stability_bounds walks, then the mass scale walks again
      const StabilityBounds b = stability_bounds(lattice, el, 0, 0);
      sink += stable_time_step(Integrator::SymplecticEuler, b, 0);
      sink += relaxation_mass_scale(lattice, el)[7];
    }
    auto t1 = C::now();
    for (int i = 0; i < 10; ++i) {
      TimeStepChoice c = choose_time_step(scene, lattice, el);
      sink += relaxation_mass_scale(el, c.row_stiffness_n_m)[7];
    }
    auto t2 = C::now();
    std::cout << "two walks " << std::chrono::duration<double, std::milli>(t1 - t0).count() / 10 << " ms, one walk + dt search "
              << std::chrono::duration<double, std::milli>(t2 - t1).count() / 10 << " ms\n";
  }
  std::cout << sink << "\n";
}

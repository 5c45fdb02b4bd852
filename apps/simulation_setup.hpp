#pragma once
/// Scene → model steps shared by the subcommands.
#include <string>

#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"
#include "engine/sim/element_setup.hpp"

namespace vb::app {

/// Parses the scene; `precision` ("" keeps the scene's) overrides solver.precision.
Scene load_scene(const std::string& path, const std::string& precision);

struct PreparedModel {
  Lattice lattice;
  ElementArrays elements;
};

/// Voxelises the shapes, builds the lattice and the per-element arrays.
PreparedModel prepare_model(const Scene& scene);

}  // namespace vb::app

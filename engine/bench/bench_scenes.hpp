#pragma once
/// The scenes `voxbreast bench` sweeps: a self-weight column with a closed form, and the bundled
/// breast phantom (at its own spacing, or resampled finer for a ~1.5M-element model).
#include <optional>
#include <string>
#include <vector>

#include "engine/lattice/lattice.hpp"
#include "engine/scene/scene.hpp"

namespace vb::bench {

/// A column held at its base, hanging under its own weight: the top sags by ρgL²/(2E) in the
/// small-strain 1-D solution (docs/VALIDATION.md, column under self-weight).
struct ColumnClosedForm {
  double length_m = 0;           ///< free length, from the anchor plane to the top face (m)
  double top_z_m = 0;            ///< world z of the top face (m)
  double youngs_modulus_pa = 0;  ///< small-strain E of the tissue (every law keeps it)
  double density_kg_m3 = 0;
  double gravity_m_s2 = 0;
  double sag_m() const { return density_kg_m3 * gravity_m_s2 * length_m * length_m / (2 * youngs_modulus_pa); }
};

struct BenchScene {
  std::string name;
  Scene scene;         ///< base settings; each case applies its knobs to a copy
  LabelVolume volume;  ///< voxels at the finest resolution; a case's lattice merges `downsample`³ of them
  std::optional<ColumnClosedForm> column;
};

/// Column of nxy × nxy × nz free voxels of spacing h (tissue E = 20 kPa, ρ = 1000 kg/m³) on
/// 4 held base layers, so that downsample 1, 2 and 4 all keep the same free body and anchor
/// plane. Damping γ = 2ω₁ (critical for the first axial mode).
BenchScene column_scene(int nxy, int nz, double spacing_m);

/// Lattice spacing that resamples the bundled phantom (18,413 elements at 4 mm) to about 1.5M
/// elements: 4 mm × (18,413 / 1.5M)^(1/3) (the study's phantom_large, the throughput's breast_large).
constexpr double kLargePhantomSpacing = 0.00092;

/// A CT scene (the bundled phantom's scene.toml) resampled at `spacing_m` (0: the scene's own).
/// Throws vb::Error when the scene is not an image scene or its files cannot be read.
BenchScene image_scene(const std::string& name, const std::string& scene_path, double spacing_m);

}  // namespace vb::bench

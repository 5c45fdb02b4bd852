#pragma once
/// Landmark pairs of a fit's observation (docs/FIT.md): a CSV with the header
///   x_mm,y_mm,z_mm,dx_mm,dy_mm,dz_mm[,sigma_mm]
/// one landmark per row: its position in the model's image and its displacement to the observed
/// posture (LPS, mm); sigma_mm its uncertainty (else the fit's).
#include <string>
#include <vector>

#include "engine/fit/observation.hpp"

namespace vb {

/// Throws vb::Error naming the file and row for a missing column or a bad number.
std::vector<Landmark> read_fit_landmarks(const std::string& path);

}  // namespace vb

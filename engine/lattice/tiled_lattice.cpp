#include "engine/lattice/tiled_lattice.hpp"

#include "engine/error.hpp"

namespace vb {

Lattice tile_lattice(const Lattice& lattice, int copies, int tissue_stride) {
  require(copies >= 1, "a tiled lattice needs at least one copy", "fit.batch");
  const std::size_t n = lattice.element_count();
  const std::size_t tissues = lattice.tissue_names.size();
  require(tissue_stride == 0 || (tissue_stride >= int(tissues) &&
                                 std::size_t(copies - 1) * std::size_t(tissue_stride) + tissues <= 256),
          std::to_string(copies) + " copies of " + std::to_string(tissues) + " tissues need more than 256 tissue ids",
          "fit.batch", "use a smaller batch");
  Lattice out = lattice;
  const std::size_t layer = std::size_t(lattice.dims[0]) * std::size_t(lattice.dims[1]);
  const std::size_t pitch = layer * std::size_t(lattice.dims[2] + 1);  // voxels from one copy to the next
  out.dims[2] = copies * (lattice.dims[2] + 1) - 1;
  const std::size_t voxels = layer * std::size_t(out.dims[2]);
  require(voxels < 0x7fffffffu, "the batch's grid has too many voxels for 32-bit indexing", "fit.batch",
          "use a smaller batch");
  out.voxel_of_element.resize(n * std::size_t(copies));
  out.tissue_of_element.resize(n * std::size_t(copies));
  out.element_of_voxel.assign(voxels, -1);
  for (int c = 0; c < copies; ++c)
    for (std::size_t e = 0; e < n; ++e) {
      const std::size_t f = std::size_t(c) * n + e;
      out.voxel_of_element[f] = std::uint32_t(lattice.voxel_of_element[e] + std::size_t(c) * pitch);
      out.tissue_of_element[f] = std::uint8_t(lattice.tissue_of_element[e] + c * tissue_stride);
      out.element_of_voxel[out.voxel_of_element[f]] = std::int32_t(f);
    }
  out.connection_count = lattice.connection_count * std::size_t(copies);
  if (tissue_stride > 0) {
    out.tissue_names.assign(std::size_t(copies - 1) * std::size_t(tissue_stride) + tissues, "");
    for (int c = 0; c < copies; ++c)
      for (std::size_t t = 0; t < tissues; ++t)
        out.tissue_names[std::size_t(c * tissue_stride) + t] = lattice.tissue_names[t] + "@" + std::to_string(c);
  }
  return out;
}

}  // namespace vb

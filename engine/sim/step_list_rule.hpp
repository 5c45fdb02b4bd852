#pragma once
/// When GPUs step over a list of the free elements (VB_STEP_LIST, kernels/common.cl) by default:
/// models above a size, of which at least a quarter are held. Measured on the H200 with the
/// phantom (docs/PERFORMANCE.md, "Step list"): from 56k up the list paid for every
/// law and integrator but hyperelastic relaxation, which lost 4–8% at 56k–64k and 1–2% at 76k and
/// gained 1–6% from 90k, so it takes the list from a larger size. Below ~50k the list lost for
/// every law and integrator (up to 32%): each pass there is bound by its chain of dependent loads,
/// which the list lengthens.
#include <cstddef>

namespace vb {

constexpr std::size_t kStepListMinElements = 65536, kStepListMinElementsHyperelasticRelaxation = 81920;

constexpr bool default_step_list(bool gpu, std::size_t elements, std::size_t held, bool hyperelastic_relaxation) {
  const std::size_t from = hyperelastic_relaxation ? kStepListMinElementsHyperelasticRelaxation : kStepListMinElements;
  return gpu && elements > from && 4 * held >= elements;
}

}  // namespace vb

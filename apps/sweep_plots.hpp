#pragma once
/// The sweep's PNG plots, drawn by scripts/plot_sweep.py (Python 3 + matplotlib).
#include <string>

namespace vb::app {

/// Runs `python3 plot_sweep.py DIR` (the script from $VOXBREAST_PLOT_SWEEP, else the source
/// tree's scripts/); returns a line saying what happened. Never throws: plots are a convenience,
/// the sweep's results are complete without them.
std::string draw_sweep_plots(const std::string& sweep_dir);

/// history.png of a fit folder, drawn by scripts/plot_fit.py ($VOXBREAST_PLOT_FIT overrides);
/// "" when drawn, else what happened.
std::string draw_fit_plot(const std::string& fit_dir);

}  // namespace vb::app

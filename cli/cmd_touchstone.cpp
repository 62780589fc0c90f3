// isolink touchstone: a Touchstone file read and fitted as the cable would be (order, error per
// entry, passivity, DC extrapolation), as text or JSON. isolink export-touchstone: a link spec's
// native cable as a .s4p from the AC analysis (the ground truth of the measured-cable path).
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/touchstone_export.h"
#include "base/file_io.h"
#include "cli/commands.h"
#include "netlists/link/link_spec.h"
#include "netlists/link/touchstone_cable.h"
#include "reports/touchstone_png.h"

namespace isolink::cli {
namespace {

struct TouchstoneArgs {
  std::string file;
  std::vector<int> ports;
  double tolerance = 1e-3;
  bool json = false;
  bool rational = false;
  std::string plot;  // PNG path, "" for none
};

nlohmann::json matrix_json(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < m.rows(); ++i) {
    nlohmann::json r = nlohmann::json::array();
    for (int j = 0; j < m.cols(); ++j) r.push_back(std::isfinite(m(i, j)) ? m(i, j) : 0.0);
    rows.push_back(r);
  }
  return rows;
}

nlohmann::json fit_json(const link::TouchstoneCable& c) {
  const FitResult& f = c.fit;
  nlohmann::json j;
  j["file"] = c.data.source;
  j["ports"] = c.data.ports;
  j["port_map"] = c.ports;
  j["differential"] = c.differential;
  j["reference_ohm"] = c.data.z0;
  j["points"] = c.data.freqs.size();
  j["f_min_hz"] = c.data.freqs.front();
  j["f_max_hz"] = c.data.freqs.back();
  j["poles"] = f.model.poles.size();
  j["states"] = f.model.order();
  j["rms_error"] = f.rms_error;
  j["max_error"] = f.error;
  j["max_error_hz"] = f.error_frequency;
  j["entry_max_error"] = matrix_json(f.entry_error);
  j["orders_tried"] = f.orders_tried;
  j["order_rms_errors"] = f.errors;
  j["passive_as_fitted"] = c.passivity.passive;
  j["min_eigenvalue_s"] = c.passivity.min_eigenvalue;
  j["min_eigenvalue_hz"] =
      std::isfinite(c.passivity.at_frequency) ? nlohmann::json(c.passivity.at_frequency) : "inf";
  j["perturbations"] = c.passivity.perturbation_iterations;
  j["min_eigenvalue_after_s"] = c.passivity.enforced_min_eigenvalue;
  j["dc_extrapolated"] = c.dc_extrapolated;
  if (c.dc_extrapolated) j["dc_resistance_ohm"] = matrix_json(c.dc_resistance);
  j["dc_conductance_s"] = matrix_json(c.dc_conductance);
  const reports::TouchstoneCurves k = reports::touchstone_curves(c);  // the model as simulated
  j["simulated_rms_error"] = k.rms_error;
  j["simulated_max_error"] = k.max_error;
  j["simulated_max_error_hz"] = k.max_error_hz;
  j["uniform_line"] = c.line.has_value();
  if (c.line) {
    const link::CableModel& m = c.line->model;
    j["delay_diff_s"] = c.line->delay_diff;
    j["z_diff_ohm"] = c.line->z_diff;
    if (!c.differential) {
      j["delay_cm_s"] = c.line->delay_cm;
      j["z_cm_ohm"] = c.line->z_cm;
    }
    j["r_dc_ohm"] = m.r_dc;
    j["skin_sections"] = m.skin.size();
    j["dielectric_branches"] = m.dielectric.size();
  } else if (c.line_rms_error > 0) {
    j["uniform_line_rms_error"] = c.line_rms_error;
  }
  return j;
}

int run_touchstone(const TouchstoneArgs& a) {
  StatusOr<Touchstone> t = read_touchstone_file(a.file);
  if (!t) {
    std::fprintf(stderr, "%s\n", t.status().message().c_str());
    return 2;
  }
  auto c = link::fit_touchstone_cable(*t, a.ports, a.tolerance, !a.rational);
  if (!c) {
    std::fprintf(stderr, "%s\n", c.status().message().c_str());
    return 2;
  }
  const link::TouchstoneCable& cable = **c;
  if (!a.plot.empty())
    if (Status s = reports::write_touchstone_png(cable, a.plot); !s.ok()) {
      std::fprintf(stderr, "%s\n", s.message().c_str());
      return 2;
    }
  if (a.json) {
    std::printf("%s\n", fit_json(cable).dump(2).c_str());
    return 0;
  }
  const FitResult& f = cable.fit;
  std::printf("%s: %d-port %s, %zu points %.4g Hz .. %.4g Hz, reference %g ohm\n", a.file.c_str(),
              t->ports, cable.differential ? "(differential)" : "(single-ended)", t->freqs.size(),
              t->freqs.front(), t->freqs.back(), t->z0);
  std::printf("fit: %zu poles (%d states), RMS |S_fit - S| %.3g, largest %.3g at %.4g Hz\n",
              f.model.poles.size(), f.model.order(), f.rms_error, f.error, f.error_frequency);
  if (cable.line)
    std::printf("passivity: by construction (every R, L and C of the line's ladder is >= 0)\n");
  else
    std::printf(
        "passivity: %s (smallest eigenvalue of Re Y %.3g S at %.4g Hz); after %d "
        "perturbations %.3g S\n",
        cable.passivity.passive ? "passive as fitted" : "enforced", cable.passivity.min_eigenvalue,
        cable.passivity.at_frequency, cable.passivity.perturbation_iterations,
        cable.passivity.enforced_min_eigenvalue);
  if (!cable.passivity.passive) {
    const reports::TouchstoneCurves k = reports::touchstone_curves(cable);
    std::printf(
        "the model simulated (after enforcement): RMS |S_fit - S| %.3g, largest %.3g at "
        "%.4g Hz\n",
        k.rms_error, k.max_error, k.max_error_hz);
  }
  if (cable.dc_extrapolated)
    std::printf(
        "below %.4g Hz: extrapolated as a lumped pi section, DC series R %.4g ohm (P), "
        "%.4g ohm (N)\n",
        t->freqs.front(), cable.dc_resistance(0, 0),
        cable.dc_resistance(cable.dc_resistance.rows() - 1, cable.dc_resistance.cols() - 1));
  if (cable.line) {
    const link::MeasuredLine& l = *cable.line;
    std::printf(
        "a uniform line (no poles): its delay carried by the native cable's ladder; differential "
        "%.4g ns at %.4g ohm",
        l.delay_diff * 1e9, l.z_diff);
    if (!cable.differential)
      std::printf(", common mode %.4g ns at %.4g ohm", l.delay_cm * 1e9, l.z_cm);
    std::printf("; DC %.4g ohm per line, %zu skin sections, %zu dielectric branches\n",
                l.model.r_dc, l.model.skin.size(), l.model.dielectric.size());
  } else if (cable.line_rms_error > 0) {
    std::printf("as a uniform line: %.3g RMS off, above the tolerance; fitted rationally\n",
                cable.line_rms_error);
  }
  if (!a.plot.empty()) std::printf("plot: %s\n", a.plot.c_str());
  return 0;
}

struct ExportArgs {
  std::string spec;
  std::string output;
  analysis::TouchstoneExportOptions opt;
};

int run_export_touchstone(const ExportArgs& a) {
  StatusOr<link::LinkSpec> spec = link::read_link_spec_file(a.spec);
  if (!spec) {
    std::fprintf(stderr, "%s\n", spec.status().message().c_str());
    return 2;
  }
  StatusOr<Touchstone> t = analysis::cable_touchstone(spec->cable, a.opt);
  if (!t) {
    std::fprintf(stderr, "%s\n", t.status().message().c_str());
    return 2;
  }
  const std::string comment = fmt::format(
      "isolink export-touchstone {}: the cable of '{}' from the AC analysis\nports: 1 = tx P, "
      "2 = tx N, 3 = rx P, 4 = rx N, single-ended to the chassis",
      a.spec, spec->name);
  if (Status s = write_file_atomic(a.output, write_touchstone(*t, comment)); !s.ok()) {
    std::fprintf(stderr, "%s\n", s.message().c_str());
    return 2;
  }
  std::fprintf(stderr, "wrote %s (%zu points, %g .. %g Hz)\n", a.output.c_str(), t->freqs.size(),
               t->freqs.front(), t->freqs.back());
  return 0;
}

}  // namespace

void add_touchstone_command(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<TouchstoneArgs>();
  CLI::App* cmd =
      app.add_subcommand("touchstone",
                         "Read a Touchstone file (.s2p, .s4p) and fit it as a cable: order, error, "
                         "passivity, DC extrapolation");
  cmd->add_option("file", args->file, "Touchstone file")->required();
  cmd->add_option("--ports", args->ports,
                  "A 4-port's file ports for tx P, tx N, rx P, rx N (default 1 2 3 4)")
      ->expected(4);
  cmd->add_option("--tolerance", args->tolerance, "Largest RMS |S_fit - S| accepted")
      ->check(CLI::Range(1e-9, 0.5));
  cmd->add_flag("--json", args->json, "JSON on standard output");
  cmd->add_flag("--rational", args->rational,
                "Fit a long line rationally, not as a uniform line first (cable.uniform_line: "
                "false)");
  cmd->add_option("--plot", args->plot,
                  "Draw the file against the fit (differential magnitude and phase, the error "
                  "per frequency) into this PNG");
  cmd->callback([args, exit_code] { *exit_code = run_touchstone(*args); });

  auto ex = std::make_shared<ExportArgs>();
  CLI::App* e = app.add_subcommand(
      "export-touchstone",
      "Write a link spec's native cable as a .s4p from the AC analysis (ports 1 = tx P, "
      "2 = tx N, 3 = rx P, 4 = rx N)");
  e->add_option("spec", ex->spec, "Link spec (YAML)")->required();
  e->add_option("-o,--output", ex->output, "Output .s4p file")->required();
  e->add_option("--fstart", ex->opt.f_start, "First frequency, Hz (default 10e3)");
  e->add_option("--fstop", ex->opt.f_stop, "Last frequency, Hz (default 500e6)");
  e->add_option("--points", ex->opt.points, "Frequencies (default 500)");
  e->add_flag("--log", ex->opt.log_spacing, "Log-spaced frequencies (default: linear, as a VNA)");
  e->callback([ex, exit_code] { *exit_code = run_export_touchstone(*ex); });
}

}  // namespace isolink::cli

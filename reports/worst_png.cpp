#include "reports/worst_png.h"

#include <fmt/format.h>

#include <cmath>

#include "reports/wave_png.h"
#include "reports/worst_report.h"

namespace isolink::reports {

Status render_worst_pngs(const analysis::WorstResult& r, const std::string& spec_name,
                         const traffic::EncodingOptions& enc, const std::string& dir,
                         std::vector<std::string>* files) {
  for (const analysis::DirectionWorst& d : r.directions) {
    for (const analysis::WorstMetric& m : d.metrics) {
      const Waveform w = analysis::synthesize(d.edge, m.traffic, enc, 0, m.record);
      StatusOr<eye::CheckResult> c = eye::check_waveform(w, d.rules);
      if (!c) return c.status().with_context("worst-case image " + m.name);
      size_t marked = 0;
      double best = INFINITY;
      for (size_t i = 0; i < c->pulses.size(); ++i)
        if (std::abs(c->pulses[i].a - m.pulse_time) < best)
          best = std::abs(c->pulses[i].a - m.pulse_time), marked = i;
      const bool volts = m.name == "vstart" || m.name == "vend";
      const std::string value =
          volts ? fmt::format("{:.3f} V", m.value) : fmt::format("{:.1f} ns", m.value * 1e9);
      const std::string margin =
          volts ? fmt::format("{:+.3f} V", m.margin) : fmt::format("{:+.1f} ns", m.margin * 1e9);
      WavePanel panel{.direction = fmt::format("{}: worst {}", d.description, m.name),
                      .time = w.time,
                      .diff = w.columns[0],
                      .rules = &d.rules,
                      .result = &*c,
                      .marked = marked,
                      .mark_label = fmt::format("{} {} (margin {})", m.name, value, margin)};
      const std::string name =
          fmt::format("worst_{}_{}.png", link::direction_name(d.direction), m.name);
      WaveReportInfo info{.spec = spec_name + " - worst case over all traffic",
                          .source = reproduce_stimulus(m, d.direction)};
      if (Status s = render_wave_png({panel}, info, dir + "/" + name); !s.ok()) return s;
      files->push_back(name);
    }
  }
  return Status::Ok();
}

}  // namespace isolink::reports

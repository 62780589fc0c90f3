#include "analysis/touchstone_export.h"

#include <fmt/format.h>

#include <cmath>

#include "netlists/link/cards.h"
#include "solver/ac.h"
#include "solver/vector_fit.h"

namespace isolink::analysis {

StatusOr<Touchstone> cable_touchstone(const link::CableSpec& cable,
                                      const TouchstoneExportOptions& opt) {
  if (!(opt.f_start > 0) || !(opt.f_stop > opt.f_start) || !std::isfinite(opt.f_stop))
    return Status::Error(
        fmt::format("export-touchstone: the band {:g}..{:g} Hz must be > 0 and "
                    "rising",
                    opt.f_start, opt.f_stop));
  if (opt.points < 2 || opt.points > 100000)
    return Status::Error(fmt::format("export-touchstone: {} points (2..100000)", opt.points));
  if (!(opt.z0 > 0) || !std::isfinite(opt.z0))
    return Status::Error("export-touchstone: the reference impedance must be > 0");
  const std::vector<std::string> ports = {"p1", "p2", "p3", "p4"};
  std::vector<Card> cards;
  if (Status s = link::add_cable(cards, "cab", ports[0], ports[1], ports[2], ports[3], cable,
                                 opt.edge_time);
      !s.ok())
    return s;
  for (int j = 0; j < 4; ++j)
    cards.push_back(link::make_card('v', fmt::format("vport{}", j + 1), {ports[j], "0"},
                                    {link::number_arg(0)}));
  Circuit circuit;
  if (Status s = link::add_cards(circuit, cards); !s.ok()) return s;
  if (Status s = circuit.finalize(); !s.ok()) return s;
  StatusOr<AcAnalysis> ac = AcAnalysis::create(circuit);
  if (!ac) return ac.status();
  std::vector<Probe> current(4);
  for (int j = 0; j < 4; ++j) {
    StatusOr<Probe> p = parse_probe(circuit, fmt::format("i(vport{})", j + 1));
    if (!p) return p.status();
    current[j] = *p;
  }
  Touchstone t;
  t.source = "isolink export-touchstone";
  t.ports = 4;
  t.z0 = opt.z0;
  t.parameter = "S";
  t.format = "RI";
  for (int k = 0; k < opt.points; ++k) {
    const double x = static_cast<double>(k) / (opt.points - 1);
    const double f = opt.log_spacing ? opt.f_start * std::pow(opt.f_stop / opt.f_start, x)
                                     : opt.f_start + (opt.f_stop - opt.f_start) * x;
    if (Status s = ac->factor(f); !s.ok()) return s;
    Eigen::MatrixXcd y(4, 4);
    for (int j = 0; j < 4; ++j) {
      AcAnalysis::Vector b(static_cast<size_t>(circuit.unknown_count()) + 1, 0.0);
      if (Status s = ac->add_excitation(fmt::format("vport{}", j + 1), 1.0, b); !s.ok()) return s;
      const AcAnalysis::Vector x_sol = ac->solve_factored(b);
      // i(v) flows from the port node through the source: the current into the cable is -i(v).
      for (int i = 0; i < 4; ++i) y(i, j) = -(x_sol[current[i].a] - x_sol[current[i].b]);
    }
    t.freqs.push_back(f);
    t.s.push_back(s_from_y(y, opt.z0));
    if (!t.s.back().allFinite())
      return Status::Error(fmt::format("export-touchstone: no finite S at {:g} Hz", f));
  }
  return t;
}

}  // namespace isolink::analysis

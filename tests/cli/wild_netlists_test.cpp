// Netlists "from the wild" (issue 13): every file in data/wild either matches ngspice within
// 0.5 % of ngspice's peak-to-peak on each probe, or is refused with a file:line:col error that
// names the feature. isolink runs with its defaults (what `isolink sim` gives a user); ngspice
// runs with tight tolerances. See data/wild/README.md for the header comments that drive it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "analysis/simulate.h"
#include "ngspice_runner.h"

namespace isolink {
namespace {

namespace fs = std::filesystem;
const std::string kWild = std::string(ISOLINK_TEST_DATA_DIR) + "/wild";

struct Header {
  std::vector<std::string> probes;
  std::string refused;    // expected error text, empty when the netlist must run
  std::string tran;       // .tran card for ngspice, empty: the netlist's
  std::string reference;  // netlist ngspice runs instead (same circuit), empty: this one
};

Header read_header(const std::string& path) {
  Header h;
  std::ifstream in(path);
  std::string line;
  const std::string tag = "* isolink-test: ";
  while (std::getline(in, line)) {
    if (line.rfind(tag, 0) != 0) continue;
    std::istringstream ls(line.substr(tag.size()));
    std::string what;
    ls >> what;
    std::string rest;
    std::getline(ls, rest);
    rest.erase(0, rest.find_first_not_of(' '));
    if (what == "probes") {
      std::istringstream ps(rest);
      for (std::string p; ps >> p;) h.probes.push_back(p);
    } else if (what == "refused") {
      h.refused = rest;
    } else if (what == "ngspice-tran") {
      h.tran = rest;
    } else if (what == "reference") {
      h.reference = kWild + "/" + rest.substr(0, rest.find(' '));
    }
  }
  return h;
}

std::vector<std::string> wild_files() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(kWild))
    if (e.path().extension() == ".cir") names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

class WildNetlist : public ::testing::TestWithParam<std::string> {};

TEST_P(WildNetlist, MatchesNgspiceOrIsRefused) {
  const std::string path = kWild + "/" + GetParam();
  const Header h = read_header(path);
  ASSERT_TRUE(!h.probes.empty() || !h.refused.empty()) << path << ": no isolink-test header";
  StatusOr<Netlist> netlist = read_spice_file(path);
  StatusOr<analysis::SimulationResult> mine = Status::Error("not run");
  if (netlist)
    mine = analysis::simulate_netlist(*netlist, analysis::SimulationRequest{.probes = h.probes});
  const Status& status = !netlist ? netlist.status() : mine.status();
  if (!h.refused.empty()) {
    ASSERT_FALSE(status.ok()) << path << " ran, but must be refused with: " << h.refused;
    // file:line:col: error: <feature> is not supported (...)
    const std::string& m = status.message();
    const std::string head = path + ":";
    // The error's line (warnings come before it: a skipped .model of another type, say).
    std::size_t at = m.find(head);
    while (at != std::string::npos) {
      const std::size_t eol = std::min(m.find('\n', at), m.size());
      if (m.substr(at, eol - at).find(": error: ") != std::string::npos) break;
      at = m.find(head, eol);
    }
    ASSERT_NE(at, std::string::npos) << m;
    int line = 0, col = 0;
    char rest[32] = {};
    ASSERT_EQ(std::sscanf(m.c_str() + at + head.size(), "%d:%d: %31[^:]", &line, &col, rest), 3)
        << m;
    EXPECT_GT(line, 0);
    EXPECT_GT(col, 0);
    EXPECT_STREQ(rest, "error") << m;
    EXPECT_NE(m.find(h.refused), std::string::npos) << m;
    return;
  }
  ASSERT_TRUE(status.ok()) << status.message();
  const std::string work = ::testing::TempDir() + "/wild";
  auto ng = testing::run_ngspice(h.reference.empty() ? path : h.reference, h.probes, work,
                                 testing::kNgspiceTight, h.tran);
  ASSERT_TRUE(ng.ok()) << ng.status().message();
  ASSERT_GT(ng->samples(), 20u);
  ASSERT_NEAR(mine->wave.time.back(), ng->time.back(), 1e-12 * ng->time.back());
  for (std::size_t k = 0; k < h.probes.size(); ++k) {
    const auto& col = ng->columns[k];
    const auto [lo, hi] = std::minmax_element(col.begin(), col.end());
    const double pp = *hi - *lo;
    ASSERT_GT(pp, 0.0) << h.probes[k] << ": flat in ngspice, nothing to compare";
    const double d = testing::max_abs_difference(mine->wave, k, *ng, k);
    EXPECT_LE(d, 0.005 * pp) << GetParam() << " " << h.probes[k] << ": max |isolink - ngspice| "
                             << d << " against peak-to-peak " << pp;
    std::printf("%s %s: max |dev| %.3g %% of p-p %.4g\n", GetParam().c_str(), h.probes[k].c_str(),
                100 * d / pp, pp);
  }
}

INSTANTIATE_TEST_SUITE_P(Wild, WildNetlist, ::testing::ValuesIn(wild_files()),
                         [](const ::testing::TestParamInfo<std::string>& p) {
                           std::string name = p.param.substr(0, p.param.size() - 4);
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

}  // namespace
}  // namespace isolink

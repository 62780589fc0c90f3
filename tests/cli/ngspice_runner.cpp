#include "ngspice_runner.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace isolink::testing {

StatusOr<Waveform> run_ngspice(const std::string& netlist, const std::vector<std::string>& probes,
                               const std::string& work_dir, const std::string& extra,
                               const std::string& tran) {
  namespace fs = std::filesystem;
  // Each call in a folder of its own under work_dir: ctest runs the Trap and Gear cases of one
  // netlist at once, and a shared deck or data file raced (one run read the other's output).
  fs::create_directories(work_dir);
  std::string unique = (fs::path(work_dir) / "run.XXXXXX").lexically_normal().string();
  if (!mkdtemp(unique.data())) return Status::Error("cannot create a folder under " + work_dir);
  const std::string stem = fs::path(netlist).stem().string();
  // No "//" in paths: ngspice reads it as a comment.
  const std::string dir = unique;
  const std::string deck = dir + "/" + stem + ".ngspice.cir";
  const std::string data = dir + "/" + stem + ".ngspice.txt";
  std::ifstream in(netlist);
  if (!in) return Status::Error("cannot read " + netlist);
  std::ofstream out(deck);
  std::string line;
  while (std::getline(in, line)) {
    std::string l = line;
    for (auto& ch : l) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (l.rfind(".end", 0) == 0 &&
        (l.size() == 4 || std::isspace(static_cast<unsigned char>(l[4]))))
      continue;
    if (!tran.empty() && l.rfind(".tran", 0) == 0 &&
        (l.size() == 5 || std::isspace(static_cast<unsigned char>(l[5])))) {
      line = "* (replaced) " +
             line;  // a + continuation of it would be an error: keep .tran on one line
      out << line << "\n" << tran << "\n";
      continue;
    }
    if (l.rfind(".include", 0) == 0) {  // make includes absolute
      std::string path = line.substr(8);
      path.erase(0, path.find_first_not_of(" \t\""));
      path.erase(path.find_last_not_of(" \t\"") + 1);
      line = ".include " + (fs::absolute(fs::path(netlist).parent_path() / path)).string();
    }
    if (l.rfind(".lib", 0) == 0 && l.size() > 4 && std::isspace(static_cast<unsigned char>(l[4]))) {
      std::istringstream ws(line.substr(4));  // .lib FILE SECTION: make FILE absolute
      std::string file, section;
      if (ws >> file >> section) {
        if (file.size() > 1 && (file[0] == '"' || file[0] == '\''))
          file = file.substr(1, file.size() - 2);
        line =
            ".lib " + fs::absolute(fs::path(netlist).parent_path() / file).string() + " " + section;
      }
    }
    out << line << "\n";
  }
  out << extra << "\n.control\nset wr_singlescale\nset wr_vecnames\noption numdgt=12\nrun\nwrdata "
      << data;
  for (const auto& p : probes) {  // ngspice names a branch current NAME#branch
    if ((p[0] == 'i' || p[0] == 'I') && p.size() > 3 && p[1] == '(')
      out << " " << p.substr(2, p.size() - 3) << "#branch";
    else
      out << " " << p;
  }
  out << "\n.endc\n.end\n";
  out.close();
  fs::remove(data);
  const std::string cmd = "ngspice -b " + deck + " > " + dir + "/" + stem + ".ngspice.log 2>&1";
  (void)std::system(cmd.c_str());  // ngspice -b exits 1 even after a good run
  if (!fs::exists(data)) return Status::Error("ngspice failed on " + deck + " (see its .log)");
  std::ifstream din(data);
  std::getline(din, line);  // header
  Waveform w;
  for (const auto& p : probes) w.add_column(p, {});
  while (std::getline(din, line)) {
    std::istringstream ls(line);
    double t;
    if (!(ls >> t)) continue;
    if (!w.time.empty() && t <= w.time.back()) continue;
    w.time.push_back(t);
    for (auto& c : w.columns) {
      double v;
      ls >> v;
      c.push_back(v);
    }
  }
  din.close();
  fs::remove_all(dir);  // kept only when ngspice failed, for its .log
  return w;
}

double max_abs_difference(const Waveform& a, size_t ka, const Waveform& b, size_t kb,
                          double t_from) {
  double worst = 0;
  for (size_t i = 0; i < b.samples(); ++i) {
    if (b.time[i] < t_from || b.time[i] > a.time.back()) continue;
    worst = std::max(worst, std::fabs(a.value_at(ka, b.time[i]) - b.columns[kb][i]));
  }
  return worst;
}

}  // namespace isolink::testing

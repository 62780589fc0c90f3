#include "analysis/sweep_mpi.h"

#include <fmt/format.h>
#include <mpi.h>

#include <chrono>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <thread>

namespace isolink::analysis::sweep {

namespace {

constexpr int kTagResult = 1;  // worker -> 0: the last point's CSV row ("" on the first request)
constexpr int kTagWork = 2;    // 0 -> worker: the next point index, -1 = no more

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void send_index(long long index, int to) {
  MPI_Send(&index, 1, MPI_LONG_LONG, to, kTagWork, MPI_COMM_WORLD);
}

// Waits for the next worker message without spinning a core (OpenMPI's blocking receive polls).
std::pair<int, std::string> receive_result() {
  MPI_Status st;
  int flag = 0;
  for (int i = 0;; ++i) {
    MPI_Iprobe(MPI_ANY_SOURCE, kTagResult, MPI_COMM_WORLD, &flag, &st);
    if (flag) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(i < 100 ? 1 : 10));
  }
  int n = 0;
  MPI_Get_count(&st, MPI_CHAR, &n);
  std::string buf(static_cast<size_t>(n), '\0');
  MPI_Recv(buf.data(), n, MPI_CHAR, st.MPI_SOURCE, kTagResult, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return {st.MPI_SOURCE, buf};
}

// Rank 0 with nothing to hand out: every worker gets -1 on its first request.
void release_workers(int size) {
  for (int left = size - 1; left > 0; --left) {
    const auto [from, row] = receive_result();
    send_index(-1, from);
  }
}

void worker(const SweepSpec& s, const link::PartLibrary& parts, const SweepOptions& opt) {
  PointOptions popt = opt.point;  // each rank finds point 0's start points itself: the same
  if (popt.start_points.empty()) popt.start_points = sweep_start_points(s, parts, popt);
  std::string row;  // empty: the first request
  for (;;) {
    MPI_Send(row.data(), static_cast<int>(row.size()), MPI_CHAR, 0, kTagResult, MPI_COMM_WORLD);
    long long index = -1;
    MPI_Recv(&index, 1, MPI_LONG_LONG, 0, kTagWork, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (index < 0) return;
    row = results_row(run_point(s, parts, static_cast<size_t>(index), popt));
  }
}

}  // namespace

bool mpi_launched() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(v)) return true;
  return false;
}

MpiWorld mpi_start() {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) MPI_Init(nullptr, nullptr);
  MpiWorld w;
  MPI_Comm_rank(MPI_COMM_WORLD, &w.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &w.size);
  return w;
}

void mpi_stop() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}

StatusOr<SweepOutcome> run_sweep_mpi(const SweepSpec& s, const link::PartLibrary& parts,
                                     const SweepOptions& opt_in, const MpiWorld& world) {
  const double t0 = now_seconds();
  SweepOptions opt = opt_in;
  if (opt.keep_waves) opt.point.waves_dir = opt.out_dir + "/waves";
  if (world.rank != 0) {
    worker(s, parts, opt);
    return SweepOutcome{};
  }
  std::error_code ec;
  std::filesystem::create_directories(opt.out_dir, ec);
  if (!ec && opt.keep_waves) std::filesystem::create_directories(opt.point.waves_dir, ec);
  if (ec) {
    release_workers(world.size);
    return Status::Error(
        fmt::format("{}: error: cannot create the folder: {}", opt.out_dir, ec.message()));
  }
  StatusOr<std::unique_ptr<ResultLog>> log = ResultLog::open(s, opt);
  if (!log) {
    release_workers(world.size);
    return log.status();
  }
  ResultLog& L = **log;
  const std::vector<size_t> todo_list = L.todo();
  if (opt.on_pool_ready) opt.on_pool_ready();  // rank 0 runs no point: no pool of its own
  std::deque<size_t> todo(todo_list.begin(), todo_list.end());
  const RowShape shape = row_shape(s);
  int active = world.size - 1;
  while (active > 0) {
    const auto [from, row] = receive_result();
    if (!row.empty()) {
      std::string line = row;
      while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
      StatusOr<PointResult> r = parse_results_row(line, shape);
      if (r)
        L.add(*r);
      else
        std::fprintf(stderr, "sweep: rank %d sent a row that does not parse (%s): %s\n", from,
                     r.status().message().c_str(), line.c_str());
    }
    if (todo.empty() || !L.status().ok()) {  // a row that could not be written stops the sweep
      send_index(-1, from);
      --active;
    } else {
      send_index(static_cast<long long>(todo.front()), from);
      todo.pop_front();
    }
  }
  if (Status st = L.status(); !st.ok()) return st;
  SweepOutcome out;
  out.skipped = L.skipped();
  finish_sweep(s, L.results(), &out);
  out.seconds = now_seconds() - t0;
  return out;
}

}  // namespace isolink::analysis::sweep

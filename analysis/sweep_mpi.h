// isolink sweep across MPI ranks (built with ISOLINK_MPI, OpenMPI from Debian):
//
//   mpirun -np 5 isolink sweep SWEEP.yaml -o DIR     # rank 0 coordinates, ranks 1-4 run points
//
// Every rank reads the sweep file and the part library itself. Rank 0 hands point indices out on
// request (dynamic: a worker asks for the next point when it has sent its last row back), writes
// results.csv as rows come in (then the front end writes summary.json and the plots on rank 0,
// reports/sweep_report.h): the same files as a threaded run (rows in completion order, run
// times aside). Each worker runs one point at a time, so start one
// rank per core plus one for the coordinator, which sleeps between messages. Waveforms
// (--keep-waves) are written by the workers into DIR/waves (a shared folder across machines).
// Outside mpirun (or with one rank) `isolink sweep` is the threaded run.
//
// Contract: as run_sweep's (sweep_run.h); every rank must call run_sweep_mpi with the same spec
// and options, and only rank 0's outcome holds results.
#pragma once

#include "analysis/sweep_run.h"

namespace isolink::analysis::sweep {

// True when the process was started by an MPI launcher (OpenMPI's or a PMI environment).
bool mpi_launched();

struct MpiWorld {
  int rank = 0;
  int size = 1;
};
// MPI_Init (once per process) and the rank and size of MPI_COMM_WORLD.
MpiWorld mpi_start();
void mpi_stop();

// The sweep over the world's ranks (size >= 2). Rank 0 returns the outcome; workers return an
// empty outcome. When rank 0 cannot start (its output folder, --resume), the workers are sent
// home and every rank returns.
StatusOr<SweepOutcome> run_sweep_mpi(const SweepSpec& s, const link::PartLibrary& parts,
                                     const SweepOptions& opt, const MpiWorld& world);

}  // namespace isolink::analysis::sweep

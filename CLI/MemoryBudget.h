// `--memory`: the budget a command keeps its volumes under, and the label-map reader that
// switches to a downsampled proxy (io/LabelProxy.h) when a label map would not fit.
#pragma once

#include "repose/io/VolumeIO.h"
#include "repose/util/Memory.h"
#include "repose/volume/Volume.h"

#include <string>

namespace repose::cli {

class ArgParser;

// Declares `--memory BYTES` with what the command does above the budget.
void declareMemoryOption(ArgParser& p, const std::string& aboveIt);

// "512M", "1G", "2.5G", "300K", or bytes; empty: half the physical memory. Throws UsageError.
double parseMemoryBudget(const std::string& text);

// The budget of one rank of an MPI job (--mpi): `memory` parsed, or (empty) half the RAM shared
// by the ranks on this node (Open MPI says how many there are).
double rankMemoryBudget(const std::string& memory);
// Worker threads of one rank: `threads` when > 0, else this node's cores shared by its ranks.
int rankThreads(int threads);

// Read options for a volume read in core under `budget`: the reader refuses, naming the file and
// the numbers, when its estimate exceeds what the budget leaves beside what the process holds now
// (Core's memoryLeftWithin: the rule the workbench and Python read by too).
ReadOptions readOptionsWithin(double budget, bool progress = true);

// Reads the label map at `path` in core when voxels * bytesPerVoxelNeeded fit in `budget`;
// otherwise (NIfTI only) builds its mode proxy through a slice cache, coarse enough to fit.
// `factor` receives 1 or the proxy's factor.
Volume readLabelsWithinBudget(const std::string& path, double budget, double bytesPerVoxelNeeded,
                              int& factor);

}  // namespace repose::cli

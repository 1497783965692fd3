#pragma once
// Consensus of the per-chunk clusterings (clusterslam_spec.md §4): Iterative Voting
// Consensus (Nguyen & Caruana, ICDM 2007) on sparse label vectors, one entry per chunk.
#include <vector>

#include "core/options_reader.h"
#include "core/tracklet_table.h"

namespace cslam {

/// Chunking and consensus parameters.
struct ConsensusOptions {
  int chunk_length = 100;       ///< frames per chunk; 100 indoor, 200 outdoor [paper]
  int chunk_overlap = 25;       ///< frames shared by adjacent chunks [paper / ours outdoor]
  double link_overlap = 0.5;    ///< [ours] initial partition: chunk clusters a, b of adjacent
                                ///< chunks are linked when |a∩b| >= this × max(|a∩S|, |b∩S|),
                                ///< S = the landmarks labelled in both chunks
  int max_iterations = 100;     ///< IVC sweeps before giving up on stability
  int min_cluster_size = 10;    ///< [ours] smaller consensus clusters → label -1 (unreliable)
  void Check() const;
  void Load(OptionsReader& reader);
};

/// The clustering of one chunk: labels[k] is the cluster of landmarks[k] (any integers >= 0;
/// their values only matter within the chunk).
struct ChunkLabels {
  std::vector<int> landmarks;
  std::vector<int> labels;
};

/// Diagnostics of one consensus run.
struct ConsensusSummary {
  int initial_clusters = 0;  ///< after the union-find initialisation
  int iterations = 0;        ///< IVC sweeps run
  bool converged = false;    ///< false: stopped at max_iterations
  int dropped_landmarks = 0; ///< in clusters below min_cluster_size
};

/// Consensus labels for landmark ids 0..num_landmarks-1: -1 for landmarks in no chunk or in a
/// dropped cluster, else 0..K-1 numbered by each cluster's smallest landmark id. `chunks`
/// must be in temporal order (adjacent entries = adjacent chunks). Missing labels [ours]: the
/// Hamming distance between a landmark and a centre counts only the chunks where both have a
/// label, divided by their number.
std::vector<int> ConsensusLabels(const std::vector<ChunkLabels>& chunks, int num_landmarks,
                                 const ConsensusOptions& options,
                                 ConsensusSummary* summary = nullptr);

/// The chunks of `range` (absolute frames) per SplitIntoChunks.
std::vector<FrameRange> ChunksOf(FrameRange range, const ConsensusOptions& options);

}  // namespace cslam

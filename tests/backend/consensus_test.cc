#include "backend/consensus.h"

#include <gtest/gtest.h>

#include "backend/labelling.h"
#include "core/errors.h"

namespace cslam {
namespace {

ConsensusOptions MinSize(int m) {
  ConsensusOptions o;
  o.min_cluster_size = m;
  return o;
}

// Three chunks over 60 landmarks in two true groups (even ids / odd ids); each chunk sees a
// sliding subset, so many labels are missing.
std::vector<ChunkLabels> SlidingChunks() {
  std::vector<ChunkLabels> chunks(3);
  for (int m = 0; m < 3; ++m)
    for (int l = 20 * m; l < 20 * m + 30 && l < 60; ++l) {
      chunks[m].landmarks.push_back(l);
      chunks[m].labels.push_back(l % 2 == 0 ? 3 * m : 3 * m + 1);  // chunk-specific label ids
    }
  return chunks;
}

std::vector<int> Parity(int n) {
  std::vector<int> v(n);
  for (int i = 0; i < n; ++i) v[i] = i % 2;
  return v;
}

TEST(Consensus, RecoversTheCommonPartitionWithMissingLabels) {
  ConsensusSummary s;
  const auto labels = ConsensusLabels(SlidingChunks(), 60, MinSize(1), &s);
  EXPECT_EQ(LabellingVariation(labels, Parity(60)), 0.0);
  EXPECT_EQ(s.initial_clusters, 2);
  EXPECT_TRUE(s.converged);
  EXPECT_EQ(labels[0], 0);  // numbered by smallest landmark id
  EXPECT_EQ(labels[1], 1);
}

TEST(Consensus, InvariantToRelabellingAChunk) {
  auto chunks = SlidingChunks();
  const auto before = ConsensusLabels(chunks, 60, MinSize(1));
  for (int& a : chunks[1].labels) a = 100 - a;  // a permutation of chunk 1's labels
  EXPECT_EQ(ConsensusLabels(chunks, 60, MinSize(1)), before);
}

TEST(Consensus, OutvotesAOneChunkMistake) {
  auto chunks = SlidingChunks();
  // Landmark 44 (even) is seen by chunks 1, 2 and an extra one; chunk 2 wrongly puts it
  // with the odd ones: two votes to one.
  ChunkLabels extra;
  for (int l = 40; l < 60; ++l) extra.landmarks.push_back(l), extra.labels.push_back(l % 2);
  chunks.push_back(extra);
  for (size_t k = 0; k < chunks[2].landmarks.size(); ++k)
    if (chunks[2].landmarks[k] == 44) chunks[2].labels[k] = 7;
  const auto labels = ConsensusLabels(chunks, 60, MinSize(1));
  EXPECT_EQ(labels[44], labels[0]);
  EXPECT_EQ(LabellingVariation(labels, Parity(60)), 0.0);
}

TEST(Consensus, ALandmarkSeenInOneChunkFollowsItsLabelThere) {
  auto chunks = SlidingChunks();
  chunks[2].landmarks.push_back(70);  // only in chunk 2, with the odd group's label
  chunks[2].labels.push_back(7);
  const auto labels = ConsensusLabels(chunks, 80, MinSize(1));
  EXPECT_EQ(labels[70], labels[1]);
  EXPECT_EQ(labels[75], -1);  // in no chunk
}

TEST(Consensus, DropsClustersBelowTheMinimumSize) {
  auto chunks = SlidingChunks();
  // Landmarks 0..4 form their own small group in chunk 0.
  for (size_t k = 0; k < 5; ++k) chunks[0].labels[k] = 9;
  ConsensusSummary s;
  const auto labels = ConsensusLabels(chunks, 60, MinSize(10), &s);
  for (int l = 0; l < 5; ++l) EXPECT_EQ(labels[l], -1);
  EXPECT_EQ(s.dropped_landmarks, 5);
  for (int l = 5; l < 60; ++l) EXPECT_EQ(labels[l] >= 0, true);
  EXPECT_NE(labels[6], labels[7]);
}

TEST(Consensus, ChunksOfShiftsToTheRange) {
  ConsensusOptions o;
  const auto chunks = ChunksOf({50, 250}, o);
  ASSERT_EQ(chunks.size(), 3u);
  EXPECT_EQ(chunks[0], (FrameRange{50, 150}));
  EXPECT_EQ(chunks[1], (FrameRange{125, 225}));
  EXPECT_EQ(chunks[2].end, 250);
}

TEST(Consensus, OptionsCheck) {
  ConsensusOptions o;
  o.chunk_overlap = 100;
  EXPECT_THROW(o.Check(), ConfigError);
  EXPECT_NO_THROW(ConsensusOptions().Check());
}

}  // namespace
}  // namespace cslam

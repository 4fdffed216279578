// The hierarchical majorant grid on the host: TF-independent per-leaf
// summaries, built once per data load, and the refit of every node's
// majorant from them when a TF changes (paper section 4, DESIGN.md rule 4).
//
// Summary of a leaf, per proxy: the set of value bins (256 bins over the
// proxy's value range; one bin per label for label maps of at most 256
// values) that the proxy can take anywhere in the leaf. For a trilinear proxy
// these are the bins crossed by the interpolant of every voxel cell of the
// leaf: a cell takes every value between its corner values, and the union of
// its 12 edge intervals is exactly that range, so the summary unions the
// intervals of the voxel edges. For a nearest-lookup proxy they are the bins
// of the voxel values.
//
// Rounding: a point that rounding puts a distance e (in voxels) outside its
// node takes a value within e * (max - min) of the value at the node's face,
// which the node's cells do cover (the trilinear interpolant changes by at
// most max - min per voxel). So each bin's value range is widened by
// kPositionTolerance * (max - min) when the TFs are bounded over it; with
// kPositionTolerance = 1e-3 voxel, far above float rounding of positions
// (about 1e-4 voxel for index coordinates up to a few thousand). Label maps
// need no widening: a leaf face lies on voxel centres, half a voxel from any
// change of nearest voxel. `margin` adds whole cells around each leaf instead,
// if ever needed.
//
// Leaves share summaries: each distinct one is stored once (leaf_summary_table.h)
// and a leaf holds its id.
//
// Refit: the maximum of every TF over every bin (once per TF), then each
// distinct summary's bound as the maximum over the materials that can occur
// in it of base density times the product over its density TFs of their
// maximum over the summary's bins; each leaf takes its summary's bound, then
// every parent the maximum of its children. The cost depends on the number
// of distinct summaries, leaves and bins, not on the number of voxels.
//
// Minorants alike (SummaryMinorant): per distinct summary a lower bound of
// the extinction, from each density TF's minimum over the summary's bins
// (0 where a point may have no material); every parent the least of its
// children's. Residual ratio tracking uses them (tracking.h).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "host_volume.h"
#include "leaf_summary_table.h"
#include "mmrtm/classifier.h"
#include "mmrtm/majorant_grid_view.h"
#include "mmrtm/majorant_refit.h"

namespace mmrtm {

enum class SummaryMode : uint8_t {
  CellRanges,  // conservative: the value ranges the cells can interpolate to
  VoxelValues  // the paper's refit: the largest extinction at the leaf's voxels,
               // recomputed from the voxels at every refit; not conservative
};

struct MajorantGridOptions {
  int leafLevel = -1;  // -1: the finest level with at most kMaxAutoLeaves leaves
  int margin = 0;      // voxel cells around each leaf included in its summary
  SummaryMode summary = SummaryMode::CellRanges;
  int threads = 0;  // 0: all hardware threads
};

// The automatic leaf level: the finest whose leaf count stays within this
// budget. Finer leaves give tighter majorants (fewer null collisions) but a
// refit costs time per leaf (a 512^3 volume's 2^18 leaves refit in about
// 1 ms on 2 CPU cores, Documentation/performance.md) and finer leaves cost
// more majorant segments per ray. A 512^3 volume gets 8-cell leaves (the
// paper's level 6), a 256^3 one 4-cell leaves.
constexpr int64_t kMaxAutoLeaves = int64_t(1) << 19;
constexpr float kPositionTolerance = 1e-3f;  // voxels; see "Rounding" above

class MajorantGrid {
 public:
  // Lays out the levels over proxy 0 and builds every leaf's summary,
  // reporting the fraction of leaves done to `progress` on the calling
  // thread (a summary build reads every voxel: seconds for gigabytes).
  void Build(const std::vector<HostVolume>& proxies, const MajorantGridOptions& options,
             const std::function<void(double)>& progress = {});
  // Rebuilds the summaries of the leaves that overlap the voxel box
  // [lo, hi] (inclusive, in proxy 0's index space) after the data there changed.
  void UpdateRegion(const std::vector<HostVolume>& proxies, std::array<int, 3> lo, std::array<int, 3> hi);
  // Recomputes every majorant for the classifier's TFs and materials.
  void Refit(const Classifier& classifier);

  // The per-TF bin tables a refit reads (mmrtm/majorant_refit.h), for the
  // classifier's TFs; the CUDA refit uploads them with the summaries.
  struct RefitTables {
    std::vector<float> binMax;
    std::vector<uint64_t> binMaterials;
    bool materialMasks = true;
    // binMax by byte of a summary (RefitInputs::byteMax): the CPU refit's
    // shortcut; the CUDA refit walks the bits.
    std::vector<float> byteMax;
    // Minorants: per TF and bin MinOverRange (coefficient TFs), and per TF
    // the mask of the bins a material TF does not cover (CoversRange);
    // byteMin as byteMax.
    std::vector<float> binMin;
    std::vector<uint64_t> uncoveredBins;
    std::vector<float> byteMin;
  };
  RefitTables MakeRefitTables(const Classifier& classifier) const;
  // The distinct leaf summaries, and each leaf's id among them (both empty
  // with SummaryMode::VoxelValues, whose refit reads the voxels instead).
  const LeafSummaryTable& Summaries() const { return summaries_; }
  const std::vector<uint32_t>& LeafSummaryIds() const { return leafSummaryIds_; }
  // What the summaries hold in memory (host only: refits read them).
  size_t SummaryBytes() const { return summaries_.Bytes() + leafSummaryIds_.capacity() * sizeof(uint32_t); }
  int ProxyCount() const { return proxyCount_; }
  const MajorantGridView& View() const { return view_; }
  int LeafLevel() const { return view_.leafLevel; }
  int64_t LeafCount() const;
  int64_t NodeCount() const { return (int64_t)majorants_.size(); }
  double LastBuildSeconds() const { return buildSeconds_; }
  double LastRefitSeconds() const { return refitSeconds_; }
  const MajorantGridOptions& Options() const { return options_; }

  // The value bins of a proxy's summary.
  struct BinMap {
    float lo = 0.f, width = 1.f;
    float slack = 0.f;      // widening of every bin's value range (see "Rounding")
    bool discrete = false;  // one bin per integer value
    int Bin(float v) const;
    void Range(int bin, float* lo, float* hi) const;  // a value range that contains the bin, with slack
  };

 private:
  // Summarizes the leaves [lo, hi] with z in [z0, z1) into `tuples`: the
  // proxies' words of each, in x-fastest order over the box [lo, hi].
  void BuildLeaves(const std::vector<HostVolume>& proxies, int z0, int z1, const int lo[3], const int hi[3],
                   uint64_t* tuples);
  void SummarizeLeaf(const std::vector<HostVolume>& proxies, int lx, int ly, int lz, uint64_t* tuple);
  // Summarizes the leaves [lo, hi] (inclusive) and gives them their ids.
  void SummarizeRegion(const std::vector<HostVolume>& proxies, const int lo[3], const int hi[3],
                       const std::function<void(double)>& progress = {});
  void RefitFromVoxelValues(const Classifier& classifier);
  void RefitUpperLevels();

  MajorantGridOptions options_;
  MajorantGridView view_;
  int proxyCount_ = 0;
  std::array<Affine3, kMaxProxies> leafIndexToProxy_;  // proxy 0 index -> proxy k index
  std::array<bool, kMaxProxies> sameGrid_{};           // leafIndexToProxy_ is the identity
  std::array<BinMap, kMaxProxies> bins_;
  // Integer voxels: BinMap::Bin of every value from binTableMin_ up, so
  // that the summaries look bins up instead of dividing (empty for float).
  std::array<std::vector<int16_t>, kMaxProxies> binTables_;
  std::array<int, kMaxProxies> binTableMin_{};
  LeafSummaryTable summaries_;
  std::vector<uint32_t> leafSummaryIds_;  // per leaf
  std::vector<float> majorants_;
  std::vector<uint8_t> minorants_;  // indexed as majorants_ (MajorantGridView::minorants)
  double buildSeconds_ = 0, refitSeconds_ = 0;
};

}  // namespace mmrtm

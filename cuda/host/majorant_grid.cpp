#include "majorant_grid.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>
#include <type_traits>

#include "parallel_for.h"

namespace mmrtm {

namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The bins of a voxel block [lo, hi] (inclusive) of one proxy: each voxel's
// bin, and with `edges` every bin between the bins of neighbouring voxels
// (the range a trilinear cell takes is the union of its edge intervals, and
// the bin of the min and max of an edge are the min and max of its bins).
template <typename T>
void SummarizeBlock(const T* data, const std::array<int, 3>& dims, const int lo[3], const int hi[3],
                    const MajorantGrid::BinMap& bins, const std::vector<int16_t>& binTable, int binTableMin, bool edges,
                    uint64_t* words, std::vector<int16_t>& scratch) {
  const int nx = hi[0] - lo[0] + 1, ny = hi[1] - lo[1] + 1, nz = hi[2] - lo[2] + 1;
  scratch.resize((size_t)nx * ny * nz);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y) {
      const T* row = data + lo[0] + (int64_t)dims[0] * ((y + lo[1]) + (int64_t)dims[1] * (z + lo[2]));
      int16_t* out = &scratch[(size_t)nx * (y + (size_t)ny * z)];
      for (int x = 0; x < nx; ++x) {
        if constexpr (std::is_integral_v<T>) {
          // The table covers the values of the last full build; an edited
          // region may hold others.
          const int64_t t = (int64_t)row[x] - binTableMin;
          if (t >= 0 && t < (int64_t)binTable.size()) {
            out[x] = binTable[(size_t)t];
            continue;
          }
        }
        out[x] = (int16_t)bins.Bin((float)row[x]);
      }
    }
  // Each voxel adds the interval [b0, b1] of its bin and its forward
  // neighbours' (all contain its own bin, so their union is one interval).
  // The union over the block is kept as a difference array and set as bits
  // once at the end: two additions a voxel instead of a mask update.
  int32_t delta[kSummaryBins + 1] = {};
  int first = kSummaryBins, last = -1;  // the bins touched: the scan covers these only
  const size_t sy = (size_t)nx, sz = (size_t)nx * ny;
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y) {
      const int16_t* r = &scratch[sy * y + sz * z];
      const bool nextY = edges && y + 1 < ny, nextZ = edges && z + 1 < nz;
      for (int x = 0; x < nx; ++x) {
        int b0 = r[x], b1 = b0;
        if (edges) {
          if (x + 1 < nx) b0 = std::min(b0, (int)r[x + 1]), b1 = std::max(b1, (int)r[x + 1]);
          if (nextY) b0 = std::min(b0, (int)r[x + sy]), b1 = std::max(b1, (int)r[x + sy]);
          if (nextZ) b0 = std::min(b0, (int)r[x + sz]), b1 = std::max(b1, (int)r[x + sz]);
        }
        ++delta[b0];
        --delta[b1 + 1];
        first = std::min(first, b0);
        last = std::max(last, b1);
      }
    }
  int covered = 0;
  for (int b = first; b <= last; ++b) {
    covered += delta[b];
    if (covered > 0) words[b >> 6] |= 1ull << (b & 63);
  }
}

}  // namespace

int MajorantGrid::BinMap::Bin(float v) const {
  const int b = (int)std::floor((v - lo) / width);
  return std::clamp(b, 0, kSummaryBins - 1);
}

void MajorantGrid::BinMap::Range(int bin, float* rangeLo, float* rangeHi) const {
  if (discrete) {
    // Label value lo + bin; TFs round to the nearest integer.
    *rangeLo = lo + bin - 0.25f;
    *rangeHi = lo + bin + 0.25f;
  } else {
    // Slack for positions rounded across a node face, and for the rounding of
    // Bin(); the first and last bins also hold everything beyond them.
    const float slack = this->slack + 1e-3f * width;
    *rangeLo = lo + bin * width - slack;
    *rangeHi = bin == kSummaryBins - 1 ? kInfinity : lo + (bin + 1) * width + slack;
    if (bin == 0) *rangeLo = -kInfinity;
  }
}

int64_t MajorantGrid::LeafCount() const {
  const int L = view_.leafLevel;
  return (int64_t)view_.res[L][0] * view_.res[L][1] * view_.res[L][2];
}

void MajorantGrid::Build(const std::vector<HostVolume>& proxies, const MajorantGridOptions& options,
                         const std::function<void(double)>& progress) {
  const auto start = Clock::now();
  options_ = options;
  proxyCount_ = (int)proxies.size();
  const HostVolume& v0 = proxies.at(0);

  // Levels: leaves of leafSize cells, each level above twice as wide.
  view_ = MajorantGridView{};
  int maxCells = 1;
  for (int a = 0; a < 3; ++a) {
    view_.cells[a] = std::max(v0.dims[a] - 1, 1);
    maxCells = std::max(maxCells, view_.cells[a]);
  }
  auto leafSizeAt = [&](int level) { return std::max(1, (int)std::ceil((double)maxCells / (double)(1 << level))); };
  auto leavesAt = [&](int level) {
    int64_t n = 1;
    for (int a = 0; a < 3; ++a) n *= (view_.cells[a] + leafSizeAt(level) - 1) / leafSizeAt(level);
    return n;
  };
  int leafLevel = options.leafLevel;
  if (leafLevel < 0) {
    leafLevel = 0;
    while (leafLevel + 1 < kMaxGridLevels && leafSizeAt(leafLevel) > 1 && leavesAt(leafLevel + 1) <= kMaxAutoLeaves)
      ++leafLevel;
  }
  leafLevel = std::clamp(leafLevel, 0, kMaxGridLevels - 1);
  view_.leafLevel = leafLevel;
  const int leafSize = leafSizeAt(leafLevel);
  float maxSpacing = 0.f;
  for (int a = 0; a < 3; ++a)
    maxSpacing =
        std::max(maxSpacing, Length(Vec3{v0.indexToWorld.m[0][a], v0.indexToWorld.m[1][a], v0.indexToWorld.m[2][a]}));
  int64_t offset = 0;
  for (int l = 0; l <= leafLevel; ++l) {
    view_.nodeSize[l] = leafSize << (leafLevel - l);
    for (int a = 0; a < 3; ++a) view_.res[l][a] = (view_.cells[a] + view_.nodeSize[l] - 1) / view_.nodeSize[l];
    view_.offset[l] = offset;
    view_.worldWidth[l] = view_.nodeSize[l] * maxSpacing;
    offset += (int64_t)view_.res[l][0] * view_.res[l][1] * view_.res[l][2];
  }
  majorants_.assign(offset, 0.f);
  view_.majorants = majorants_.data();
  minorants_.assign(offset, 0);
  view_.minorants = minorants_.data();

  // Value bins per proxy, and the map from proxy 0's index space to each proxy's.
  for (int k = 0; k < proxyCount_; ++k) {
    const HostVolume& v = proxies[k];
    const auto range = v.ValueRange();
    BinMap& b = bins_[k];
    b.lo = range[0];
    bool integral = v.type != VoxelType::Float32;
    if (!integral) {
      integral = true;
      for (int64_t i = 0, n = v.VoxelCount(); i < n && integral; ++i) integral = v.Value(i) == std::floor(v.Value(i));
    }
    b.discrete = v.interpolation == Interpolation::Nearest && integral && range[1] - range[0] < kSummaryBins;
    b.width = b.discrete ? 1.f : std::max((range[1] - range[0]) / kSummaryBins, 1e-30f);
    if (!(range[1] > range[0])) b.width = 1.f;
    b.slack = v.interpolation == Interpolation::Trilinear ? kPositionTolerance * (range[1] - range[0]) : 0.f;
    binTables_[k].clear();
    if (v.type != VoxelType::Float32 && range[1] >= range[0]) {
      // At most 65,536 entries (16-bit voxels), each the bin Bin() gives.
      binTableMin_[k] = (int)range[0];
      binTables_[k].resize((size_t)((int)range[1] - (int)range[0] + 1));
      for (size_t i = 0; i < binTables_[k].size(); ++i)
        binTables_[k][i] = (int16_t)b.Bin((float)(binTableMin_[k] + (int)i));
    }
    if (options_.summary == SummaryMode::VoxelValues) continue;
    leafIndexToProxy_[k] = AffineCompose(v.View().worldToIndex, v0.indexToWorld);
    sameGrid_[k] = OnSameVoxelGrid(v, v0);
  }
  summaries_.Reset(proxyCount_);
  leafSummaryIds_.clear();
  leafSummaryIds_.shrink_to_fit();
  // The voxel-value refit reads the voxels themselves: no summaries.
  if (options_.summary == SummaryMode::CellRanges) {
    const int L = view_.leafLevel;
    const int lo[3] = {0, 0, 0}, hi[3] = {view_.res[L][0] - 1, view_.res[L][1] - 1, view_.res[L][2] - 1};
    leafSummaryIds_.resize((size_t)LeafCount());
    SummarizeRegion(proxies, lo, hi, progress);
  }
  buildSeconds_ = SecondsSince(start);
}

void MajorantGrid::SummarizeRegion(const std::vector<HostVolume>& proxies, const int lo[3], const int hi[3],
                                   const std::function<void(double)>& progress) {
  // Every leaf of the box in full first (in parallel, a layer of leaves at
  // a time), then each takes the id of its summary (in order, so that ids
  // do not depend on threads).
  const int L = view_.leafLevel, n[3] = {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1};
  const size_t stride = (size_t)proxyCount_ * kSummaryWords;
  std::vector<uint64_t> tuples((size_t)n[0] * n[1] * n[2] * stride, 0ull);
  std::atomic<int> nextLayer{0}, layersDone{0};
  const int threads = options_.threads > 0 ? options_.threads : (int)std::max(1u, std::thread::hardware_concurrency());
  RunWorkers(std::min(threads, n[2]), [&](int worker) {
    for (int z = nextLayer++; z < n[2]; z = nextLayer++) {
      BuildLeaves(proxies, lo[2] + z, lo[2] + z + 1, lo, hi, tuples.data());
      ++layersDone;
      if (worker == 0 && progress) progress((double)layersDone / n[2]);
    }
  });
  if (progress) progress(1.0);
  const uint64_t* tuple = tuples.data();
  for (int z = lo[2]; z <= hi[2]; ++z)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int x = lo[0]; x <= hi[0]; ++x, tuple += stride)
        leafSummaryIds_[(size_t)(x + (int64_t)view_.res[L][0] * (y + (int64_t)view_.res[L][1] * z))] =
            summaries_.Insert(tuple);
  // Summaries that no leaf holds any more (after an edit) go, and the
  // table's storage shrinks to what it holds.
  summaries_.Compact(leafSummaryIds_);
}

void MajorantGrid::UpdateRegion(const std::vector<HostVolume>& proxies, std::array<int, 3> lo, std::array<int, 3> hi) {
  if (options_.summary == SummaryMode::VoxelValues) return;  // its refit reads the voxels
  const auto start = Clock::now();
  const int L = view_.leafLevel, size = view_.nodeSize[L], m = options_.margin;
  int leafLo[3], leafHi[3];
  for (int a = 0; a < 3; ++a) {
    // A voxel touches the cells on both sides of it, plus the margins.
    leafLo[a] = std::clamp((lo[a] - 1 - m) / size, 0, view_.res[L][a] - 1);
    leafHi[a] = std::clamp((hi[a] + m) / size, 0, view_.res[L][a] - 1);
  }
  SummarizeRegion(proxies, leafLo, leafHi);
  buildSeconds_ = SecondsSince(start);
}

void MajorantGrid::BuildLeaves(const std::vector<HostVolume>& proxies, int z0, int z1, const int lo[3], const int hi[3],
                               uint64_t* tuples) {
  const size_t stride = (size_t)proxyCount_ * kSummaryWords;
  const int64_t nx = hi[0] - lo[0] + 1, ny = hi[1] - lo[1] + 1;
  for (int z = z0; z < z1; ++z)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int x = lo[0]; x <= hi[0]; ++x)
        SummarizeLeaf(proxies, x, y, z,
                      tuples + stride * (size_t)((x - lo[0]) + nx * ((y - lo[1]) + ny * (z - lo[2]))));
}

void MajorantGrid::SummarizeLeaf(const std::vector<HostVolume>& proxies, int lx, int ly, int lz, uint64_t* tuple) {
  thread_local std::vector<int16_t> scratch;
  const int L = view_.leafLevel, size = view_.nodeSize[L], m = options_.margin;
  const int leaf[3] = {lx, ly, lz};
  // The leaf's cells with the margin, in proxy 0's index space.
  float boxLo[3], boxHi[3];
  for (int a = 0; a < 3; ++a) {
    boxLo[a] = (float)std::max(0, leaf[a] * size - m);
    boxHi[a] = (float)std::min(view_.cells[a], (leaf[a] + 1) * size + m);
  }
  for (int k = 0; k < proxyCount_; ++k) {
    const HostVolume& v = proxies[k];
    // The voxels whose values points of the box can see in proxy k: the
    // bounding box of the box's corners, widened to whole voxels.
    int lo[3], hi[3];
    float pLo[3] = {kInfinity, kInfinity, kInfinity}, pHi[3] = {-kInfinity, -kInfinity, -kInfinity};
    for (int c = 0; c < 8; ++c) {
      Vec3 p = leafIndexToProxy_[k].ApplyPoint(
          {(c & 1) ? boxHi[0] : boxLo[0], (c & 2) ? boxHi[1] : boxLo[1], (c & 4) ? boxHi[2] : boxLo[2]});
      for (int a = 0; a < 3; ++a) {
        pLo[a] = std::min(pLo[a], p[a]);
        pHi[a] = std::max(pHi[a], p[a]);
      }
    }
    for (int a = 0; a < 3; ++a) {
      // Exact integers for a proxy on proxy 0's grid; otherwise every voxel
      // that a trilinear or nearest lookup in the box can reach.
      lo[a] = std::clamp((int)std::floor(pLo[a] + 1e-4f), 0, v.dims[a] - 1);
      hi[a] = std::clamp((int)std::ceil(pHi[a] - 1e-4f), 0, v.dims[a] - 1);
      if (!sameGrid_[k]) {
        lo[a] = std::clamp((int)std::floor(pLo[a]) - 1, 0, v.dims[a] - 1);
        hi[a] = std::clamp((int)std::ceil(pHi[a]) + 1, 0, v.dims[a] - 1);
      }
    }
    const bool edges = v.interpolation == Interpolation::Trilinear && options_.summary == SummaryMode::CellRanges;
    uint64_t* words = tuple + k * kSummaryWords;
    const std::vector<int16_t>& table = binTables_[k];
    const int tableMin = binTableMin_[k];
    switch (v.type) {
      case VoxelType::UInt8:
        SummarizeBlock(v.voxels.data(), v.dims, lo, hi, bins_[k], table, tableMin, edges, words, scratch);
        break;
      case VoxelType::Int16:
        SummarizeBlock(reinterpret_cast<const int16_t*>(v.voxels.data()), v.dims, lo, hi, bins_[k], table, tableMin,
                       edges, words, scratch);
        break;
      case VoxelType::UInt16:
        SummarizeBlock(reinterpret_cast<const uint16_t*>(v.voxels.data()), v.dims, lo, hi, bins_[k], table, tableMin,
                       edges, words, scratch);
        break;
      case VoxelType::Float32:
        SummarizeBlock(reinterpret_cast<const float*>(v.voxels.data()), v.dims, lo, hi, bins_[k], table, tableMin,
                       edges, words, scratch);
        break;
    }
  }
}

void MajorantGrid::RefitFromVoxelValues(const Classifier& c) {
  // The paper's refit: each leaf visits its voxels and takes the largest
  // extinction the classification gives at them. Its cost grows with the
  // voxel count, and a TF peak between two voxel values is missed.
  const int L = view_.leafLevel, size = view_.nodeSize[L];
  const VolumeView& v0 = c.proxies[0];
  const Affine3 indexToWorld = AffineInverse(v0.worldToIndex);
  const int* res = view_.res[L];
  ParallelFor(LeafCount(), options_.threads, [&](int64_t begin, int64_t end) {
    for (int64_t leaf = begin; leaf < end; ++leaf) {
      const int cell[3] = {(int)(leaf % res[0]), (int)((leaf / res[0]) % res[1]),
                           (int)(leaf / ((int64_t)res[0] * res[1]))};
      int lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        lo[a] = cell[a] * size;
        hi[a] = std::min((cell[a] + 1) * size, (&v0.nx)[a] - 1);
      }
      float majorant = 0.f;
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x)
            majorant = std::max(majorant, c.Classify(indexToWorld.ApplyPoint({(float)x, (float)y, (float)z})).sigma_t);
      majorants_[view_.offset[L] + leaf] = majorant;
    }
  });
}

MajorantGrid::RefitTables MajorantGrid::MakeRefitTables(const Classifier& c) const {
  // Per TF and bin: the TF's maximum (coefficient TFs) or the materials it
  // can pick (material TFs) over the bin's value range.
  RefitTables t;
  t.binMax.assign((size_t)c.tfCount * kSummaryBins, 0.f);
  t.byteMax.assign((size_t)c.tfCount * kSummaryBytes * 256, 0.f);
  t.binMaterials.assign((size_t)c.tfCount * kSummaryBins, 0);
  t.binMin.assign((size_t)c.tfCount * kSummaryBins, 0.f);
  t.byteMin.assign((size_t)c.tfCount * kSummaryBytes * 256, kInfinity);
  t.uncoveredBins.assign((size_t)c.tfCount * kSummaryWords, 0);
  t.materialMasks = c.materialCount <= 64;
  // The refit reads the byte tables of density TFs only.
  std::vector<char> density((size_t)c.tfCount, 0);
  for (int m = 0; m < c.materialCount; ++m)
    for (int b = 0; b < c.materials[m].densityBindingCount; ++b)
      density[(size_t)c.bindings[c.materials[m].bindingBegin + b].tf] = 1;
  for (int i = 0; i < c.tfCount; ++i) {
    const TransferFunctionView& tf = c.tfs[i];
    for (int b = 0; b < kSummaryBins; ++b) {
      float lo, hi;
      bins_[tf.proxy].Range(b, &lo, &hi);
      if (IsMaterialTF(tf.type)) {
        uint64_t mask = 0;
        for (int e = 0; e < tf.count; ++e)
          if (tf.EntryInRange(e, lo, hi)) mask |= 1ull << (tf.materials[e] & 63);
        t.binMaterials[(size_t)i * kSummaryBins + b] = mask;
        if (!tf.CoversRange(lo, hi)) t.uncoveredBins[(size_t)i * kSummaryWords + b / 64] |= 1ull << (b % 64);
      } else {
        float v[kMaxTFChannels];
        tf.MaxOverRange(lo, hi, v);
        t.binMax[(size_t)i * kSummaryBins + b] = v[0];
        tf.MinOverRange(lo, hi, v);
        t.binMin[(size_t)i * kSummaryBins + b] = v[0];
      }
    }
    // Each byte value's maximum (minimum): that of the value without its
    // lowest bit, and that bit's bin (32 x 255 entries a TF).
    for (int byte = 0; byte < kSummaryBytes && density[(size_t)i] && !IsMaterialTF(tf.type); ++byte) {
      float* table = &t.byteMax[((size_t)i * kSummaryBytes + byte) * 256];
      float* lower = &t.byteMin[((size_t)i * kSummaryBytes + byte) * 256];
      for (int v = 1; v < 256; ++v) {
        const size_t bin = (size_t)i * kSummaryBins + byte * 8 + CountTrailingZeros64(v);
        table[v] = std::max(table[v & (v - 1)], t.binMax[bin]);
        lower[v] = std::min(lower[v & (v - 1)], t.binMin[bin]);
      }
    }
  }
  return t;
}

void MajorantGrid::Refit(const Classifier& c) {
  const auto start = Clock::now();
  if (options_.summary == SummaryMode::VoxelValues) {
    std::fill(minorants_.begin(), minorants_.end(), 0);  // no lower bounds from voxel values
    RefitFromVoxelValues(c);
    RefitUpperLevels();
    refitSeconds_ = SecondsSince(start);
    return;
  }
  const RefitTables tables = MakeRefitTables(c);
  RefitInputs in;
  for (int k = 0; k < proxyCount_; ++k) in.summaries[k] = summaries_.Words(k);
  in.binMax = tables.binMax.data();
  in.binMaterials = tables.binMaterials.data();
  in.materialMasks = tables.materialMasks;
  in.byteMax = tables.byteMax.data();
  in.binMin = tables.binMin.data();
  in.uncoveredBins = tables.uncoveredBins.data();
  in.byteMin = tables.byteMin.data();
  // Each distinct summary (the same function as the CUDA refit), its leaves,
  // then the levels above.
  std::vector<float> bounds(summaries_.Count());
  std::vector<uint8_t> lowerBounds(summaries_.Count());
  ParallelFor((int64_t)bounds.size(), options_.threads, [&](int64_t begin, int64_t end) {
    for (int64_t s = begin; s < end; ++s) {
      bounds[(size_t)s] = SummaryMajorant(c, in, s);
      lowerBounds[(size_t)s] = EncodeMinorant(bounds[(size_t)s], SummaryMinorant(c, in, s));
    }
  });
  float* leafMajorants = majorants_.data() + view_.offset[view_.leafLevel];
  uint8_t* leafMinorants = minorants_.data() + view_.offset[view_.leafLevel];
  ParallelFor(LeafCount(), options_.threads, [&](int64_t begin, int64_t end) {
    for (int64_t leaf = begin; leaf < end; ++leaf) {
      leafMajorants[leaf] = bounds[leafSummaryIds_[(size_t)leaf]];
      leafMinorants[leaf] = lowerBounds[leafSummaryIds_[(size_t)leaf]];
    }
  });
  RefitUpperLevels();
  refitSeconds_ = SecondsSince(start);
}

void MajorantGrid::RefitUpperLevels() {
  // Bottom-up: each node the maximum of its children, and the least of their
  // minorants; a level's nodes in parallel where there are many.
  for (int l = view_.leafLevel - 1; l >= 0; --l) {
    const int* r = view_.res[l];
    const int64_t rows = (int64_t)r[1] * r[2];
    ParallelFor(rows, rows * r[0] >= 32768 ? options_.threads : 1, [&](int64_t begin, int64_t end) {
      for (int64_t row = begin; row < end; ++row)
        for (int x = 0; x < r[0]; ++x)
          UpperNodeBounds(view_, majorants_.data(), minorants_.data(), l, x, (int)(row % r[1]), (int)(row / r[1]));
    });
  }
}

}  // namespace mmrtm

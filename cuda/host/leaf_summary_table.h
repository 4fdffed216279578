// The majorant grid's leaf summaries, each distinct one stored once.
// Host-only set-up code.
//
// A leaf's summary is, per proxy, the 256-bin set of values the proxy can
// take in it (majorant_grid.h). Most leaves share theirs with many others
// (empty air, uniform tissue, one label): the five reference scenes of
// Documentation/accuracy.md have 5,200 to 22,400 distinct summaries among
// 93,000 to 380,000 leaves. So the table keeps each distinct summary (the
// tuple of its proxies' words) once and a leaf holds the 4-byte id of its
// own: 4 bytes a leaf instead of 32 per proxy, and a refit bounds each
// distinct summary once and then copies the bound to its leaves.
//
// Ids are stable until Compact(); an insert that finds the summary already
// stored returns the stored id. Each proxy's words are contiguous
// (kSummaryWords a summary), which is the layout RefitInputs reads, so a
// refit takes the summary id where it took a leaf index.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "mmrtm/majorant_refit.h"

namespace mmrtm {

class LeafSummaryTable {
 public:
  // Empties the table for summaries of `proxyCount` proxies.
  void Reset(int proxyCount);
  // The id of the summary whose proxy k's words are tuple[k * kSummaryWords ...],
  // stored first if new.
  uint32_t Insert(const uint64_t* tuple);
  // Drops the summaries that no id in `ids` refers to and renumbers `ids`.
  // Returns how many were dropped.
  size_t Compact(std::vector<uint32_t>& ids);

  size_t Count() const { return count_; }
  int ProxyCount() const { return proxyCount_; }
  // Proxy k's words of every summary: kSummaryWords per id.
  const uint64_t* Words(int proxy) const { return words_[proxy].data(); }
  const std::vector<uint64_t>& WordVector(int proxy) const { return words_[proxy]; }
  // What the table holds (the words and its hash index).
  size_t Bytes() const;

 private:
  uint64_t Hash(const uint64_t* tuple) const;
  bool Equals(uint32_t id, const uint64_t* tuple) const;
  void Rehash(size_t slots);

  int proxyCount_ = 0;
  size_t count_ = 0;
  std::vector<uint64_t> words_[kMaxProxies];
  // Open addressing, linear probing: id + 1 per slot, 0 when empty; a power
  // of two slots, at most half full.
  std::vector<uint32_t> slots_;
};

}  // namespace mmrtm

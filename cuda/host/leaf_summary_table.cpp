#include "leaf_summary_table.h"

#include <algorithm>
#include <stdexcept>

#include "mmrtm/rng.h"

namespace mmrtm {

void LeafSummaryTable::Reset(int proxyCount) {
  if (proxyCount < 0 || proxyCount > kMaxProxies) throw std::invalid_argument("LeafSummaryTable: bad proxy count");
  proxyCount_ = proxyCount;
  count_ = 0;
  for (auto& w : words_) w.clear();
  slots_.assign(1024, 0u);
}

uint64_t LeafSummaryTable::Hash(const uint64_t* tuple) const {
  // Each word folded into the running hash and mixed (the renderer's MixBits).
  uint64_t h = 0x9e3779b97f4a7c15ull;
  for (int i = 0; i < proxyCount_ * kSummaryWords; ++i) h = MixBits(h ^ tuple[i]) + 0x9e3779b97f4a7c15ull;
  return h;
}

bool LeafSummaryTable::Equals(uint32_t id, const uint64_t* tuple) const {
  for (int k = 0; k < proxyCount_; ++k)
    if (!std::equal(tuple + k * kSummaryWords, tuple + (k + 1) * kSummaryWords,
                    words_[k].begin() + (size_t)id * kSummaryWords))
      return false;
  return true;
}

void LeafSummaryTable::Rehash(size_t slots) {
  slots_.assign(slots, 0u);
  std::vector<uint64_t> tuple((size_t)proxyCount_ * kSummaryWords);
  for (uint32_t id = 0; id < count_; ++id) {
    for (int k = 0; k < proxyCount_; ++k)
      std::copy_n(words_[k].begin() + (size_t)id * kSummaryWords, kSummaryWords, tuple.begin() + k * kSummaryWords);
    size_t s = Hash(tuple.data()) & (slots_.size() - 1);
    while (slots_[s]) s = (s + 1) & (slots_.size() - 1);
    slots_[s] = id + 1;
  }
}

uint32_t LeafSummaryTable::Insert(const uint64_t* tuple) {
  if (slots_.empty()) throw std::logic_error("LeafSummaryTable::Insert before Reset");
  size_t s = Hash(tuple) & (slots_.size() - 1);
  for (; slots_[s]; s = (s + 1) & (slots_.size() - 1))
    if (Equals(slots_[s] - 1, tuple)) return slots_[s] - 1;
  const uint32_t id = (uint32_t)count_++;
  for (int k = 0; k < proxyCount_; ++k)
    words_[k].insert(words_[k].end(), tuple + k * kSummaryWords, tuple + (k + 1) * kSummaryWords);
  slots_[s] = id + 1;
  if (2 * count_ > slots_.size()) Rehash(2 * slots_.size());
  return id;
}

size_t LeafSummaryTable::Compact(std::vector<uint32_t>& ids) {
  std::vector<uint32_t> renumbered(count_, UINT32_MAX);
  for (uint32_t id : ids) renumbered[id] = 0;
  uint32_t kept = 0;
  for (size_t id = 0; id < count_; ++id) {
    if (renumbered[id] == UINT32_MAX) continue;
    renumbered[id] = kept;
    if (kept != id)  // moves down only: the source lies after the destination
      for (int k = 0; k < proxyCount_; ++k)
        std::copy_n(words_[k].begin() + id * kSummaryWords, kSummaryWords,
                    words_[k].begin() + (size_t)kept * kSummaryWords);
    ++kept;
  }
  const size_t dropped = count_ - kept;
  count_ = kept;
  for (int k = 0; k < proxyCount_; ++k) {
    words_[k].resize(count_ * kSummaryWords);
    words_[k].shrink_to_fit();
  }
  for (uint32_t& id : ids) id = renumbered[id];
  size_t slots = 1024;
  while (slots < 2 * count_) slots *= 2;
  Rehash(slots);
  return dropped;
}

size_t LeafSummaryTable::Bytes() const {
  size_t bytes = slots_.capacity() * sizeof(uint32_t);
  for (const auto& w : words_) bytes += w.capacity() * sizeof(uint64_t);
  return bytes;
}

}  // namespace mmrtm

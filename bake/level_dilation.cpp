#include "bake/level_dilation.h"

#include <algorithm>
#include <memory>
#include <vector>

#include "bake/coverage_mask.h"
#include "bake/level_store.h"

namespace vt {
namespace {

// One pull level: per texel `channels` weighted sums then the weight, in double. Kept in a
// LevelStore of 2 * (channels + 1) floats per texel: the store only moves the doubles' bytes.
class PullLevel {
 public:
  static Expected<PullLevel> create(uint32_t w, uint32_t h, uint32_t ch, bool in_memory,
                                    const std::string& dir, bool compressed) {
    PullLevel p;
    p.w = w, p.h = h, p.ch = ch;
    VT_ASSIGN_OR_RETURN(p.store_,
                        LevelStore::create(w, h, 2 * (ch + 1), in_memory, dir, compressed));
    return p;
  }
  static uint64_t bytes(uint32_t w, uint32_t h, uint32_t ch) {
    return uint64_t(w) * h * (ch + 1) * sizeof(double);
  }
  size_t row_doubles() const { return size_t(w) * (ch + 1); }
  // Rows go to a scratch store a batch of about 4 MiB at a time, and are read so too: a
  // compressed store then (de)compresses a batch's chunks on every core, not a row at a time on
  // the dilation's thread. Rows held back are written before rows are read ahead, and a row
  // written is also seen by the rows read ahead.
  Status write(uint32_t y, const double* row) {
    if (store_->in_memory()) return store_->write_rows(y, 1, reinterpret_cast<const float*>(row));
    if (y >= read_y0_ && y < read_y0_ + read_rows_)
      std::copy_n(row, row_doubles(), read_.data() + size_t(y - read_y0_) * row_doubles());
    if (pending_rows_ > 0 && y != pending_y0_ + pending_rows_) VT_RETURN_IF_ERROR(flush());
    if (pending_rows_ == 0) pending_y0_ = y;
    pending_.resize(size_t(pending_rows_ + 1) * row_doubles());
    std::copy_n(row, row_doubles(), pending_.data() + size_t(pending_rows_) * row_doubles());
    return ++pending_rows_ == batch_rows() ? flush() : Status::Ok();
  }
  Status read(uint32_t y, double* row) {
    if (store_->in_memory()) return store_->read(y, y + 1, reinterpret_cast<float*>(row));
    if (y < read_y0_ || y >= read_y0_ + read_rows_) {
      VT_RETURN_IF_ERROR(flush());
      read_y0_ = y, read_rows_ = std::min(batch_rows(), h - y);
      read_.resize(size_t(read_rows_) * row_doubles());
      VT_RETURN_IF_ERROR(store_->read(y, y + read_rows_, reinterpret_cast<float*>(read_.data())));
    }
    std::copy_n(read_.data() + size_t(y - read_y0_) * row_doubles(), row_doubles(), row);
    return Status::Ok();
  }

  uint32_t w = 0, h = 0, ch = 0;

 private:
  // Writes the rows held back (a read of one of them asks first).
  Status flush() {
    const uint32_t rows = pending_rows_;
    pending_rows_ = 0;
    return rows == 0 ? Status::Ok()
                     : store_->write_rows(pending_y0_, rows,
                                          reinterpret_cast<const float*>(pending_.data()));
  }

  uint32_t batch_rows() const {
    return uint32_t(std::clamp<size_t>((size_t(4) << 20) / (row_doubles() * sizeof(double)), 1,
                                       std::max(h, 1u)));
  }
  std::unique_ptr<LevelStore> store_;
  std::vector<double> pending_, read_;
  uint32_t pending_y0_ = 0, pending_rows_ = 0, read_y0_ = 0, read_rows_ = 0;
};

// The pull: level k's row j is the sum of level k-1's rows 2j and 2j+1, texel i of texels 2i
// and 2i+1, added in that order from 0 (as pull_push does, row by row, texel by texel).
class PullCascade {
 public:
  explicit PullCascade(std::vector<PullLevel>& levels) : levels_(levels) {
    for (const PullLevel& l : levels) acc_.emplace_back(l.row_doubles(), 0.0);
  }
  // Adds row y of the level below `k` (k = 0: level 0, as sums and weights).
  Status add_row(size_t k, uint32_t y, uint32_t src_w, const double* row) {
    if (k == levels_.size()) return Status::Ok();
    PullLevel& d = levels_[k];
    std::vector<double>& acc = acc_[k];
    const uint32_t n = d.ch + 1;
    for (uint32_t x = 0; x < src_w; ++x) {
      double* a = acc.data() + size_t(x / 2) * n;
      const double* s = row + size_t(x) * n;
      a[n - 1] += s[n - 1];
      for (uint32_t c = 0; c + 1 < n; ++c) a[c] += s[c];
    }
    const uint32_t src_h = k == 0 ? level0_h_ : levels_[k - 1].h;
    if (y % 2 == 0 && y + 1 < src_h) return Status::Ok();  // row 2j+1 still to come
    VT_RETURN_IF_ERROR(d.write(y / 2, acc.data()));
    VT_RETURN_IF_ERROR(add_row(k + 1, y / 2, d.w, acc.data()));
    std::fill(acc.begin(), acc.end(), 0.0);
    return Status::Ok();
  }
  void set_level0_height(uint32_t h) { level0_h_ = h; }

 private:
  std::vector<PullLevel>& levels_;
  std::vector<std::vector<double>> acc_;
  uint32_t level0_h_ = 0;
};

// The push, coarse to fine: a texel with weight takes sum / weight, one without its parent's
// value; values overwrite the level's sums in place (the first `ch` doubles of each texel).
Status push_level(PullLevel& level, PullLevel* parent) {
  const uint32_t n = level.ch + 1;
  std::vector<double> row(level.row_doubles());
  std::vector<double> up(parent ? parent->row_doubles() : 0);
  int64_t up_y = -1;
  for (uint32_t y = 0; y < level.h; ++y) {
    VT_RETURN_IF_ERROR(level.read(y, row.data()));
    if (parent && int64_t(y / 2) != up_y) {
      up_y = y / 2;
      VT_RETURN_IF_ERROR(parent->read(uint32_t(up_y), up.data()));
    }
    for (uint32_t x = 0; x < level.w; ++x) {
      double* t = row.data() + size_t(x) * n;
      const double w = t[n - 1];
      if (w > 0.0) {
        for (uint32_t c = 0; c + 1 < n; ++c) t[c] /= w;
      } else if (parent) {
        const double* p = up.data() + size_t(x / 2) * n;
        for (uint32_t c = 0; c + 1 < n; ++c) t[c] = p[c];
      }
      t[n - 1] = 1.0;
    }
    VT_RETURN_IF_ERROR(level.write(y, row.data()));
  }
  return Status::Ok();
}

uint32_t band_rows_for(const BandedDilationOptions& o, uint32_t width, uint32_t channels,
                       uint32_t height) {
  if (o.band_rows > 0) return std::min(o.band_rows, height);
  const uint64_t row = uint64_t(width) * (channels * (sizeof(float) + sizeof(double)) + 1);
  return uint32_t(std::clamp<uint64_t>(o.memory_budget / 8 / std::max<uint64_t>(row, 1), 2,
                                       std::max(height, 2u)));
}

}  // namespace

uint64_t pull_push_bytes(uint32_t width, uint32_t height, uint32_t channels) {
  return PullLevel::bytes(width, height, channels) * 4 / 3 + uint64_t(width) * height;
}

Expected<uint64_t> pull_push_banded(LevelStore& level, const CoverageMask& coverage,
                                    const BandedDilationOptions& options) {
  const uint32_t W = level.width(), H = level.height(), ch = level.channels(), n = ch + 1;
  // Pull levels down to 1x1; the coarsest take the memory budget first.
  std::vector<std::pair<uint32_t, uint32_t>> sizes;
  for (uint32_t w = W, h = H; w > 1 || h > 1;) {
    w = (w + 1) / 2, h = (h + 1) / 2;
    sizes.push_back({w, h});
  }
  const uint32_t band = band_rows_for(options, W, ch, H);
  uint64_t budget = options.memory_budget;
  budget -= std::min(budget, uint64_t(band) * W * ch * (sizeof(float) + sizeof(double)));
  std::vector<bool> in_memory(sizes.size());
  for (size_t k = sizes.size(); k-- > 0;) {
    const uint64_t b = PullLevel::bytes(sizes[k].first, sizes[k].second, ch);
    in_memory[k] = b <= budget;
    if (in_memory[k]) budget -= b;
  }
  std::vector<PullLevel> pull;
  for (size_t k = 0; k < sizes.size(); ++k) {
    // Scratch pull levels are compressed where the level they dilate is.
    VT_ASSIGN_OR_RETURN(PullLevel l,
                        PullLevel::create(sizes[k].first, sizes[k].second, ch, in_memory[k],
                                          options.scratch_dir, level.compressed()));
    pull.push_back(std::move(l));
  }

  // Pull, from level 0's rows read in bands.
  PullCascade cascade(pull);
  cascade.set_level0_height(H);
  std::vector<float> rows(size_t(band) * W * ch);
  std::vector<double> sums(size_t(W) * n);
  std::vector<uint8_t> band_coverage;
  uint64_t uncovered = 0;
  for (uint32_t y0 = 0; y0 < H; y0 += band) {
    const uint32_t y1 = std::min(H, y0 + band);
    VT_RETURN_IF_ERROR(level.read(y0, y1, rows.data()));
    VT_RETURN_IF_ERROR(coverage.read_rows(y0, y1, band_coverage));
    for (uint32_t y = y0; y < y1; ++y) {
      const float* r = rows.data() + size_t(y - y0) * W * ch;
      const uint8_t* cov = band_coverage.data() + size_t(y - y0) * W;
      for (uint32_t x = 0; x < W; ++x) {
        double* s = sums.data() + size_t(x) * n;
        const bool covered = cov[x] != 0;
        uncovered += !covered;
        for (uint32_t c = 0; c < ch; ++c) s[c] = covered ? double(r[size_t(x) * ch + c]) : 0.0;
        s[ch] = covered ? 1.0 : 0.0;
      }
      VT_RETURN_IF_ERROR(cascade.add_row(0, y, W, sums.data()));
    }
  }
  if (uncovered == 0 || uncovered == uint64_t(W) * H) return uint64_t(0);

  // Push, coarse to fine, then into level 0's uncovered texels.
  for (size_t k = pull.size(); k-- > 0;)
    VT_RETURN_IF_ERROR(push_level(pull[k], k + 1 < pull.size() ? &pull[k + 1] : nullptr));
  PullLevel& first = pull.front();
  std::vector<double> up(first.row_doubles());
  int64_t up_y = -1;
  for (uint32_t y0 = 0; y0 < H; y0 += band) {
    const uint32_t y1 = std::min(H, y0 + band);
    VT_RETURN_IF_ERROR(level.read(y0, y1, rows.data()));
    VT_RETURN_IF_ERROR(coverage.read_rows(y0, y1, band_coverage));
    for (uint32_t y = y0; y < y1; ++y) {
      if (int64_t(y / 2) != up_y) {
        up_y = y / 2;
        VT_RETURN_IF_ERROR(first.read(uint32_t(up_y), up.data()));
      }
      float* r = rows.data() + size_t(y - y0) * W * ch;
      const uint8_t* cov = band_coverage.data() + size_t(y - y0) * W;
      for (uint32_t x = 0; x < W; ++x) {
        if (cov[x]) continue;
        const double* p = up.data() + size_t(x / 2) * n;
        for (uint32_t c = 0; c < ch; ++c) r[size_t(x) * ch + c] = float(p[c]);
      }
    }
    VT_RETURN_IF_ERROR(level.write_rows(y0, y1 - y0, rows.data()));
  }
  return uncovered;
}

}  // namespace vt

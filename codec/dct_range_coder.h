// Internal to the page DCT codec: an LZMA-style binary range coder with 12-bit adaptive
// probabilities. Integer-only, so every machine decodes the same bits from the same bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vt::dct_detail {

constexpr int kProbBits = 12;
constexpr uint32_t kProbOne = 1u << kProbBits;
constexpr uint32_t kRangeTop = 1u << 24;

// p is P(bit == 0) in 1/4096; n counts observations (capped) and sets the adaptation rate, so
// an untrained context learns fast and a trained one moves slowly.
struct BitModel {
  uint16_t p = kProbOne / 2;
  uint8_t n = 0;
};

constexpr int kRateCap = 24;
// Shift per observation count: roughly 1/(n+1.5) early, 1/32 once settled.
inline constexpr uint8_t kRateShift[kRateCap + 1] = {1, 2, 2, 3, 3, 3, 3, 3, 4, 4, 4, 4, 4,
                                                     4, 4, 4, 4, 5, 5, 5, 5, 5, 5, 5, 5};

inline void adapt(BitModel& m, int bit) {
  const int shift = kRateShift[m.n];
  m.n = uint8_t(m.n + (m.n < kRateCap));
  const int p = m.p;
  // Both candidates computed so the compiler can select without a branch.
  const int down = p - (p >> shift), up = p + ((int(kProbOne) - p) >> shift);
  m.p = uint16_t(bit ? down : up);
}

class RangeEncoder {
 public:
  static constexpr bool kDecoding = false;

  explicit RangeEncoder(std::vector<uint8_t>& out) : out_(out), start_(out.size()) {}

  int bit(BitModel& m, int bit) {
    const uint32_t bound = (range_ >> kProbBits) * m.p;
    if (bit) {
      low_ += bound;
      range_ -= bound;
    } else {
      range_ = bound;
    }
    adapt(m, bit);
    while (range_ < kRangeTop) {
      range_ <<= 8;
      shift_low();
    }
    return bit;
  }

  // Equiprobable bits, most significant first.
  int direct(int value, int nbits) {
    for (int i = nbits - 1; i >= 0; i--) {
      range_ >>= 1;
      if ((value >> i) & 1) low_ += range_;
      while (range_ < kRangeTop) {
        range_ <<= 8;
        shift_low();
      }
    }
    return value;
  }

  // Picks the value in [low, low + range) with the most trailing zero bits, so the bytes that
  // would only carry zeros can be dropped (the decoder reads zeros past the end).
  void finish() {
    for (int bits = 32; bits > 0; bits--) {
      const uint64_t mask = (uint64_t(1) << bits) - 1;
      const uint64_t v = (low_ + mask) & ~mask;
      if (v < low_ + range_) {
        low_ = v;
        break;
      }
    }
    for (int i = 0; i < 5; i++) shift_low();
    // The first byte is always 0 (the interval starts inside [0, 2^32)): drop it.
    out_.erase(out_.begin() + std::ptrdiff_t(start_));
    size_t end = out_.size();
    while (end > start_ && end + 4 > out_.size() && out_[end - 1] == 0) end--;
    out_.resize(end);
  }

 private:
  void shift_low() {
    if (uint32_t(low_) < 0xFF000000u || (low_ >> 32) != 0) {
      const uint8_t carry = uint8_t(low_ >> 32);
      uint8_t temp = cache_;
      do {
        out_.push_back(uint8_t(temp + carry));
        temp = 0xFF;
      } while (--cache_size_ != 0);
      cache_ = uint8_t(low_ >> 24);
    }
    cache_size_++;
    low_ = (low_ & 0x00FFFFFFu) << 8;
  }

  std::vector<uint8_t>& out_;
  size_t start_;
  uint64_t low_ = 0;
  uint32_t range_ = 0xFFFFFFFFu;
  uint8_t cache_ = 0;
  uint64_t cache_size_ = 1;
};

// Counts the bins each context sees, to fit initial probabilities to training pages.
class BinCounter {
 public:
  static constexpr bool kDecoding = false;

  BinCounter(const BitModel* base, uint32_t (*counts)[2]) : base_(base), counts_(counts) {}

  int bit(BitModel& m, int bit) {
    counts_[&m - base_][bit]++;
    return bit;
  }
  int direct(int value, int) { return value; }

 private:
  const BitModel* base_;
  uint32_t (*counts_)[2];
};

// Reads zeros past the end of the data and counts them: a valid stream overreads at most 4
// bytes, so more means the data was cut short or is corrupt.
class RangeDecoder {
 public:
  static constexpr bool kDecoding = true;

  RangeDecoder(const uint8_t* data, size_t size) : p_(data), end_(data + size) {
    for (int i = 0; i < 4; i++) code_ = (code_ << 8) | next();
  }

  int bit(BitModel& m, int = 0) {
    const uint32_t bound = (range_ >> kProbBits) * m.p;
    const int bit = code_ >= bound;
    code_ -= bit ? bound : 0;
    range_ = bit ? range_ - bound : bound;
    adapt(m, bit);
    while (range_ < kRangeTop) {
      range_ <<= 8;
      code_ = (code_ << 8) | next();
    }
    return bit;
  }

  int direct(int, int nbits) {
    int value = 0;
    for (int i = 0; i < nbits; i++) {
      range_ >>= 1;
      int bit = 0;
      if (code_ >= range_) {
        code_ -= range_;
        bit = 1;
      }
      value = (value << 1) | bit;
      while (range_ < kRangeTop) {
        range_ <<= 8;
        code_ = (code_ << 8) | next();
      }
    }
    return value;
  }

  size_t overread() const { return overread_; }
  bool consumed_all() const { return p_ == end_; }

 private:
  uint32_t next() {
    if (p_ < end_) return *p_++;
    overread_++;
    return 0;
  }

  const uint8_t* p_;
  const uint8_t* end_;
  uint32_t range_ = 0xFFFFFFFFu;
  uint32_t code_ = 0;
  size_t overread_ = 0;
};

}  // namespace vt::dct_detail

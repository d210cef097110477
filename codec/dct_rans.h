// Internal to the page DCT codec: rANS over 16-token alphabets with adaptive frequencies, plus a
// raw bit stream. A token decodes with one table-free search over 16 cumulative counts and one
// multiply, and its model then moves toward what it saw with one 16-lane update (the rule AV1
// uses for its CDFs); two interleaved rANS states let consecutive tokens overlap. The encoder
// runs the same models forward, records each token's interval, and rANS-codes them backwards.
// Integer-only: every machine decodes the same tokens.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace vt::dct_detail {

constexpr int kTokens = 16;
constexpr int kFreqBits = 14;
constexpr uint32_t kFreqTotal = 1u << kFreqBits;
constexpr uint32_t kRansLow = 1u << 16;  // states live in [2^16, 2^32); 16-bit renormalisation
constexpr int kRateCap = 40;             // observations after which a model adapts at its slowest

// One adaptive distribution over the 16 tokens. above[t] = cumulative frequency of tokens 0..t
// (above[15] = kFreqTotal); every token keeps freq >= 1, so any token can be coded anywhere.
// cum[7] = 0 is the start of token 0, so finding a start needs no branch; cum[0] counts the
// observations an adaptive model has made (up to kRateCap), which set its adaptation rate.
struct alignas(16) TokenModel {
  uint16_t cum[8 + kTokens] = {};
  uint16_t* above() { return cum + 8; }
  const uint16_t* above() const { return cum + 8; }
  uint16_t& seen() { return cum[0]; }
  uint16_t seen() const { return cum[0]; }
};

// Adaptation shift from the observation count: fast while a context is new, 1/64 once settled.
inline int adapt_shift(int n) {
  return 4 + (n >= 12) + (n >= kRateCap);
}

// Moves the model a 2^-shift step toward "token t seen": above[i] heads for i+1 below t and for
// kFreqTotal - 15 + i from t on. Floor rounding keeps the counts ordered with gaps >= 1.
inline void adapt(TokenModel& m, int t) {
  const int shift = adapt_shift(m.seen());
  m.seen() = uint16_t(m.seen() + (m.seen() < kRateCap));
#if defined(__SSE2__)
  const __m128i tv = _mm_set1_epi16(int16_t(t - 1));
  const __m128i lo_idx = _mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7);
  const __m128i hi_idx = _mm_setr_epi16(8, 9, 10, 11, 12, 13, 14, 15);
  const __m128i one = _mm_set1_epi16(1), span = _mm_set1_epi16(int16_t(kFreqTotal - kTokens));
  const __m128i sh = _mm_cvtsi32_si128(shift);
  __m128i* p = reinterpret_cast<__m128i*>(m.above());
  const __m128i lo = _mm_load_si128(p), hi = _mm_load_si128(p + 1);
  const __m128i lo_target =
      _mm_add_epi16(_mm_add_epi16(lo_idx, one), _mm_and_si128(_mm_cmpgt_epi16(lo_idx, tv), span));
  const __m128i hi_target =
      _mm_add_epi16(_mm_add_epi16(hi_idx, one), _mm_and_si128(_mm_cmpgt_epi16(hi_idx, tv), span));
  _mm_store_si128(p, _mm_add_epi16(lo, _mm_sra_epi16(_mm_sub_epi16(lo_target, lo), sh)));
  _mm_store_si128(p + 1, _mm_add_epi16(hi, _mm_sra_epi16(_mm_sub_epi16(hi_target, hi), sh)));
#else
  for (int i = 0; i < kTokens; i++) {
    const int target = i + 1 + (i >= t ? int(kFreqTotal) - kTokens : 0);
    m.above()[i] = uint16_t(m.above()[i] + ((target - m.above()[i]) >> shift));  // C++20: floor
  }
#endif
}

// The token whose interval holds `slot` (< kFreqTotal): the number of tokens ending at or
// before it.
inline unsigned find_token(const TokenModel& m, uint32_t slot) {
#if defined(__SSE2__)
  const __m128i s = _mm_set1_epi16(int16_t(slot + 1));
  const __m128i* p = reinterpret_cast<const __m128i*>(m.above());
  const __m128i lo = _mm_cmpgt_epi16(s, _mm_load_si128(p));
  const __m128i hi = _mm_cmpgt_epi16(s, _mm_load_si128(p + 1));
  // The set lanes are a prefix (the counts ascend) and lane 15 is never set: count = first clear.
  return unsigned(__builtin_ctz(~unsigned(_mm_movemask_epi8(_mm_packs_epi16(lo, hi)))));
#else
  unsigned t = 0;
  for (int i = 0; i < kTokens; i++) t += m.above()[i] <= slot;
  return t;
#endif
}

inline uint32_t token_start(const TokenModel& m, unsigned t) {
  return m.cum[7 + t];
}

// Collects each token's interval in coding order and rANS-encodes them backwards at the end.
class RansEncoder {
 public:
  void put(const TokenModel& m, int t) {
    const uint32_t start = token_start(m, t);
    syms_.push_back({uint16_t(start), uint16_t(m.above()[t] - start)});
  }

  // Appends the rANS bytes: two 32-bit states (little-endian), then 16-bit words.
  void finish(std::vector<uint8_t>& out) {
    uint32_t x[2] = {kRansLow, kRansLow};
    words_.clear();
    for (size_t i = syms_.size(); i-- > 0;) {
      uint32_t& s = x[i & 1];
      const Sym& y = syms_[i];
      const uint32_t x_max = (kRansLow >> kFreqBits << 16) * y.freq;
      if (s >= x_max) {
        words_.push_back(uint16_t(s));
        s >>= 16;
      }
      s = ((s / y.freq) << kFreqBits) + (s % y.freq) + y.start;
    }
    for (int k = 0; k < 2; k++)
      for (int b = 0; b < 4; b++) out.push_back(uint8_t(x[k] >> (8 * b)));
    for (size_t i = words_.size(); i-- > 0;) {
      out.push_back(uint8_t(words_[i]));
      out.push_back(uint8_t(words_[i] >> 8));
    }
    syms_.clear();
  }

 private:
  struct Sym {
    uint16_t start, freq;
  };
  std::vector<Sym> syms_;
  std::vector<uint16_t> words_;  // emitted last-first; kept for its capacity
};

// Decodes from a copy of the rANS bytes followed by kPadding zero bytes, so that renormalising
// needs neither a bounds check nor a branch (a data-dependent branch there mispredicts on about
// one token in five). A valid stream reads exactly its bytes and ends with both states back at
// their initial value (`valid_end`); callers stop once `overran()`, checking at least every
// kPadding / 2 - 4 tokens.
class RansDecoder {
 public:
  static constexpr size_t kPadding = 256;

  // `padded` holds size >= 8 bytes, then kPadding zeros.
  RansDecoder(const uint8_t* padded, size_t size) : p_(padded + 8), end_(padded + size) {
    x0_ = read32(padded);
    x1_ = read32(padded + 4);
  }

  unsigned get(const TokenModel& m) {
    const uint32_t slot = x0_ & (kFreqTotal - 1);
    const unsigned t = find_token(m, slot);
    const uint32_t start = token_start(m, t);
    uint32_t x = (m.above()[t] - start) * (x0_ >> kFreqBits) + slot - start;
    // Renormalise without a branch: one would mispredict on about one token in five.
    uint16_t word;
    std::memcpy(&word, p_, 2);
    if constexpr (__BYTE_ORDER__ == __ORDER_BIG_ENDIAN__) word = __builtin_bswap16(word);
    const uint32_t renormalised = (x << 16) | word;
#if defined(__x86_64__) && defined(__GNUC__)
    // Two conditional moves; compilers turn the C++ below back into a branch.
    const uint8_t* next = p_ + 2;
    asm("cmpl %[low], %[x]\n\t"
        "cmovbl %[renormalised], %[x]\n\t"
        "cmovbq %[next], %[p]"
        : [x] "+r"(x), [p] "+r"(p_)
        : [renormalised] "r"(renormalised), [next] "r"(next), [low] "i"(kRansLow)
        : "cc");
#else
    const uint32_t small = x < kRansLow;
    x = small ? renormalised : x;
    p_ += small << 1;
#endif
    x0_ = x1_;
    x1_ = x;
    return t;
  }

  bool overran() const {
    return p_ > end_;
  }
  bool valid_end() const {
    return x0_ == kRansLow && x1_ == kRansLow && p_ == end_;
  }

 private:
  static uint32_t read32(const uint8_t* p) {
    return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
  }

  const uint8_t* p_;
  const uint8_t* end_;
  uint32_t x0_ = 0, x1_ = 0;
};

// The plane decoder is built for the baseline target and, on x86-64, for AVX2 + BMI2, picked by
// the host's CPU (codec/dct.cpp). Whether this host runs the AVX2 build; and, for tests, a switch
// that makes every decoder thread run the baseline build, so that the two can be compared.
bool plane_decoder_uses_avx2();
void force_baseline_plane_decoder(bool on);

// Raw bits, least significant first.
class BitWriter {
 public:
  void put(uint32_t value, int nbits) {
    acc_ |= uint64_t(value) << count_;
    count_ += nbits;
    while (count_ >= 8) {
      bytes_.push_back(uint8_t(acc_));
      acc_ >>= 8;
      count_ -= 8;
    }
  }
  // Pads the last byte with zeros and appends everything to `out`.
  void finish(std::vector<uint8_t>& out) {
    if (count_ > 0) bytes_.push_back(uint8_t(acc_));
    out.insert(out.end(), bytes_.begin(), bytes_.end());
    bytes_.clear();
    acc_ = 0;
    count_ = 0;
  }

 private:
  std::vector<uint8_t> bytes_;
  uint64_t acc_ = 0;
  int count_ = 0;
};

// Reads from a copy of the raw bytes followed by kPadding zero bytes, so that a refill is one
// unaligned load with no bounds check. Callers stop once `overran()`, checking at least every
// (kPadding - 8) bytes of reads.
class BitReader {
 public:
  static constexpr size_t kPadding = 256;

  // `padded` holds `size` bytes, then kPadding zeros.
  BitReader(const uint8_t* padded, size_t size)
      : start_(padded), p_(padded), bits_(uint64_t(size) * 8) {}

  // At least 56 bits become available. Bits past those stepped over are ORed in again,
  // unchanged, by the next refill.
  void refill() {
    uint64_t v;
    std::memcpy(&v, p_, 8);
    if constexpr (__BYTE_ORDER__ == __ORDER_BIG_ENDIAN__) v = __builtin_bswap64(v);
    acc_ |= v << count_;
    p_ += (63 - count_) >> 3;
    count_ |= 56;
  }
  // nbits <= 56 in total since the last refill; mask = 2^nbits - 1.
  uint32_t take(int nbits, uint32_t mask) {
    const uint32_t v = uint32_t(acc_) & mask;
    acc_ >>= nbits;
    count_ -= nbits;
    return v;
  }

  bool overran() const { return consumed() > bits_; }
  // Valid when fewer than 8 bits are left and those padding bits are zero (the bits beyond
  // them are the zeros after the data).
  bool valid_end() const { return consumed() <= bits_ && bits_ - consumed() < 8 && acc_ == 0; }

 private:
  uint64_t consumed() const { return uint64_t(p_ - start_) * 8 - uint64_t(count_); }

  const uint8_t* start_;
  const uint8_t* p_;
  uint64_t bits_;
  uint64_t acc_ = 0;
  int count_ = 0;
};

}  // namespace vt::dct_detail

// Drives the page DCT fuzz target (fuzz_dct.cpp) with bounded random and mutated inputs; the
// codec tests also run under ASan/UBSan, which turn any bad access into a failure.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <vector>

#include "common/hash.h"
#include "fuzz/fuzz_dct.cpp"

namespace vt {
namespace {

// Stops a loop after `iterations` or `seconds`, whichever comes first, so the test stays
// bounded on a slow sanitizer build.
struct Budget {
  int iterations;
  std::chrono::steady_clock::time_point end;
  Budget(int n, double seconds)
      : iterations(n),
        end(std::chrono::steady_clock::now() + std::chrono::milliseconds(int64_t(seconds * 1000))) {
  }
  bool more() { return iterations-- > 0 && std::chrono::steady_clock::now() < end; }
};

void mutate(std::vector<uint8_t>& v, Lcg64& rng) {
  const int edits = 1 + int(rng.below(4));
  for (int e = 0; e < edits; e++) {
    const size_t at = dct_fuzz::kHeaderBytes + rng.below(v.size() - dct_fuzz::kHeaderBytes + 1);
    switch (rng.below(5)) {
      case 0:  // flip a bit
        if (at < v.size()) v[at] ^= uint8_t(1u << rng.below(8));
        break;
      case 1:  // truncate
        v.resize(at);
        break;
      case 2:  // insert a byte
        v.insert(v.begin() + std::ptrdiff_t(at), uint8_t(rng.next()));
        break;
      case 3:  // erase a byte
        if (at < v.size()) v.erase(v.begin() + std::ptrdiff_t(at));
        break;
      default:  // overwrite a run with 0x00 or 0xFF
        for (size_t i = at, n = rng.below(16); i < v.size() && n > 0; i++, n--) {
          v[i] = rng.below(2) ? 0xFF : 0x00;
        }
    }
  }
}

// Runs the target on `count` independently mutated copies of `input`.
void run_mutated(const std::vector<uint8_t>& input, int count, Lcg64& rng) {
  for (int m = 0; m < count; m++) {
    auto bad = input;
    mutate(bad, rng);
    LLVMFuzzerTestOneInput(bad.data(), bad.size());
  }
}

std::vector<uint8_t> valid_page_input(uint8_t mode, uint8_t quality, uint8_t size, Lcg64& rng) {
  std::vector<uint8_t> input = {mode, quality, size};
  const dct_fuzz::Setup setup = dct_fuzz::setup_from(input.data());
  const DctTablesPtr tables = dct_fuzz::tables_for(setup);
  std::vector<uint8_t> page(size_t(setup.width) * setup.height * setup.settings.channels);
  // Smooth ramps plus some noise: many coefficient paths, not just DC.
  for (size_t i = 0; i < page.size(); i++) {
    page[i] = uint8_t((i / 3) % 200 + (rng.next() >> 29));
  }
  std::vector<uint8_t> coded;
  EXPECT_TRUE(dct_encode_page(*tables, page.data(), setup.width, setup.height, coded).ok());
  input.insert(input.end(), coded.begin(), coded.end());
  return input;
}

TEST(DctFuzz, RandomInputs) {
  Lcg64 rng{1};
  Budget budget(3000, 8.0);
  while (budget.more()) {
    std::vector<uint8_t> input(rng.below(2048));
    for (auto& v : input) v = uint8_t(rng.next());
    LLVMFuzzerTestOneInput(input.data(), input.size());
  }
}

TEST(DctFuzz, MutatedValidPages) {
  Lcg64 rng{2};
  Budget budget(3000, 10.0);
  while (budget.more()) {
    const uint8_t mode = uint8_t((rng.next() & 0x1E));  // a page, any layout, trained or not
    auto input = valid_page_input(mode, uint8_t(rng.next()), uint8_t(rng.next()), rng);
    LLVMFuzzerTestOneInput(input.data(), input.size());  // unmutated: must decode
    run_mutated(input, 8, rng);
  }
}

TEST(DctFuzz, MutatedTables) {
  Lcg64 rng{3};
  Budget budget(300, 8.0);
  while (budget.more()) {
    const dct_fuzz::Setup setup = dct_fuzz::setup_from(
        std::vector<uint8_t>{uint8_t(rng.next() & 0x1E), uint8_t(rng.next()), 0}.data());
    const auto bytes = dct_serialize_tables(*dct_fuzz::tables_for(setup));
    std::vector<uint8_t> input = {1, 0, 0};
    input.insert(input.end(), bytes.begin(), bytes.end());
    run_mutated(input, 8, rng);
  }
}

TEST(DctFuzz, ValidPagesDecode) {
  // The target itself is checked: valid input goes through the decode-twice comparison.
  Lcg64 rng{4};
  for (int i = 0; i < 32; i++) {
    auto input = valid_page_input(uint8_t(i & 0x1E), uint8_t(rng.next()), uint8_t(rng.next()), rng);
    const dct_fuzz::Setup setup = dct_fuzz::setup_from(input.data());
    const DctTablesPtr tables = dct_fuzz::tables_for(setup);
    std::vector<uint8_t> out(size_t(setup.width) * setup.height * setup.settings.channels);
    EXPECT_TRUE(
        dct_decode_page(*tables, std::span(input).subspan(3), setup.width, setup.height, out.data())
            .ok());
    EXPECT_EQ(LLVMFuzzerTestOneInput(input.data(), input.size()), 0);
  }
}

}  // namespace
}  // namespace vt

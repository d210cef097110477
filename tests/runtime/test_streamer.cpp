#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <thread>

#include "engine_hooks.h"
#include "fake_source.h"
#include "runtime/streamer.h"

namespace vt {
namespace {

using testing::CountingAllocator;
using testing::FakeSource;
using testing::small_geometry;
using testing::TestJobQueue;

std::unique_ptr<Streamer> make_streamer(std::shared_ptr<const PageSource> src, uint32_t sx,
                                        uint32_t sy, uint32_t threads, uint64_t budget = 0,
                                        uint32_t in_flight = 16, JobSystem jobs = {},
                                        Allocator allocator = {}) {
  StreamerOptions o;
  o.jobs = jobs;
  o.allocator = allocator;
  o.slots_x = sx;
  o.slots_y = sy;
  o.threads = threads;
  o.memory_budget_bytes = budget;
  o.max_in_flight = in_flight;
  o.frames_before_lowering = 3;
  auto s = Streamer::create(std::move(src), o);
  EXPECT_TRUE(s.ok()) << s.status().message();
  return std::move(s).value();
}

// A random rectangle of feedback: a view that wants level `l` around a point.
std::vector<uint32_t> random_view(std::mt19937& rng, const PageGeometry& g, size_t pixels) {
  std::vector<uint32_t> fb(pixels, kFeedbackNone);
  const uint32_t l = rng() % g.level_count();
  const uint32_t cx = rng() % g.pages_x(l), cy = rng() % g.pages_y(l);
  for (size_t i = 0; i < pixels; ++i) {
    if (rng() % 5 == 0) continue;
    const uint32_t dl = std::min<uint32_t>(l + rng() % 2, g.level_count() - 1);
    const uint32_t x = std::min<uint32_t>((cx >> (dl - l)) + rng() % 3, g.pages_x(dl) - 1);
    const uint32_t y = std::min<uint32_t>((cy >> (dl - l)) + rng() % 3, g.pages_y(dl) - 1);
    fb[i] = feedback_pack(dl, x, y);
  }
  return fb;
}

// Physical cache copy built from the uploads: slot -> (page, layer-0 bytes).
struct CpuCache {
  std::map<uint32_t, std::pair<PageId, std::vector<uint8_t>>> slots;
  uint32_t sx;
  void apply(std::vector<PageUpload> ups) {
    for (auto& u : ups)
      slots[u.slot_y * sx + u.slot_x] = {u.page, {u.layers[0].begin(), u.layers[0].end()}};
  }
};

TEST(Streamer, PropertyRandomRequestsAndEvictions) {
  // Absent pages exercise the "nearest present ancestor" rule throughout.
  auto src = std::make_shared<FakeSource>(small_geometry(13, 9), 2, [](const PageId& id) {
    return id.level < 2 && hash32(id.x * 31 + id.y * 7 + id.level) % 7 == 0;
  });
  const uint64_t slot = slot_bytes(*src);
  const uint64_t budget = (12 + 16) * slot + slot / 2;  // 12 slots + staging for 16
  auto s = make_streamer(src, 4, 4, 2, budget, 16);
  ASSERT_EQ(s->capacity(), 12u);
  CpuCache cpu{{}, 4};
  std::mt19937 rng(11);
  const PageGeometry& g = src->geometry();
  for (int frame = 0; frame < 400; ++frame) {
    const auto fb = random_view(rng, g, 64);
    const FrameStats st = s->update(fb);
    EXPECT_LE(st.lod_bias, g.level_count() - 1);
    if (rng() % 4 == 0) s->wait_idle();
    for (int k = 0; k < 3; ++k) {
      const uint32_t l = rng() % g.level_count();
      const PageId p{l, uint32_t(rng() % g.pages_x(l)), uint32_t(rng() % g.pages_y(l))};
      if (rng() % 2)
        s->evict(p);
      else
        s->request(p);
    }
    cpu.apply(s->take_uploads());
    ASSERT_TRUE(s->check_invariants().ok())
        << "frame " << frame << ": " << s->check_invariants().message();
    ASSERT_LE(s->memory_bytes(), budget);
    // Every resident page's slot holds that page's bytes.
    const PageTable table = s->page_table();
    for (const PageId& p : s->resident_pages()) {
      const PageTableEntry e = table.entry(p);
      ASSERT_TRUE(e.valid());
      ASSERT_EQ(e.level, p.level);
      auto& [page, bytes] = cpu.slots[e.slot_y * 4 + e.slot_x];
      ASSERT_EQ(page, p);
      std::vector<uint8_t> want(src->upload_bytes(0));
      FakeSource::fill(p, 0, want);
      ASSERT_EQ(bytes, want);
    }
  }
}

// Runs a fixed sequence of feedback buffers, converging after each (update + wait_idle until
// nothing changes), and returns the resident set with each slot's page. With `jobs`, the
// engine's job system does the loads: its queued jobs run before each wait.
std::vector<std::pair<uint32_t, PageId>> converge_sequence(uint32_t threads,
                                                           TestJobQueue* jobs = nullptr) {
  auto src = std::make_shared<FakeSource>(small_geometry(16, 16), 1, [](const PageId& id) {
    return id.level == 0 && (id.x * 3 + id.y) % 11 == 0;
  });
  src->set_delay_us(threads > 1 ? 50 : 0);  // let workers finish out of order
  auto s = make_streamer(src, 6, 5, threads, 0, 8, jobs ? jobs->hook() : JobSystem{});
  std::mt19937 rng(5);
  for (int step = 0; step < 25; ++step) {
    const auto fb = random_view(rng, src->geometry(), 200);
    for (int i = 0; i < 100; ++i) {
      const FrameStats st = s->update(fb);
      s->take_uploads();
      if (jobs) jobs->run_all();
      s->wait_idle();
      if (st.queued == 0 && st.mapped == 0 && s->idle()) break;
    }
    EXPECT_TRUE(s->check_invariants().ok());
  }
  std::vector<std::pair<uint32_t, PageId>> out;
  const PageTable table = s->page_table();
  for (const PageId& p : s->resident_pages()) {
    const PageTableEntry e = table.entry(p);
    out.push_back({e.slot_y * 6u + e.slot_x, p});
  }
  std::sort(out.begin(), out.end(), [](auto& a, auto& b) { return a.first < b.first; });
  return out;
}

TEST(Streamer, ResultsIndependentOfThreadCount) {
  const auto one = converge_sequence(1);
  EXPECT_GT(one.size(), 10u);
  for (uint32_t t : {2u, 8u}) {
    const auto many = converge_sequence(t);
    ASSERT_EQ(one.size(), many.size()) << t << " threads";
    for (size_t i = 0; i < one.size(); ++i) {
      EXPECT_EQ(one[i].first, many[i].first);
      EXPECT_EQ(one[i].second, many[i].second);
    }
  }
}

TEST(Streamer, JobHookGivesTheSameResultsAsThreads) {
  const auto threads = converge_sequence(2);
  TestJobQueue deferred, inline_jobs;
  inline_jobs.inline_run = true;
  for (TestJobQueue* q : {&deferred, &inline_jobs}) {
    const auto jobs = converge_sequence(0, q);  // threads ignored with a job system
    EXPECT_GT(q->submitted(), 50u);
    ASSERT_EQ(jobs.size(), threads.size()) << (q->inline_run ? "inline" : "deferred");
    for (size_t i = 0; i < jobs.size(); ++i) {
      EXPECT_EQ(jobs[i].first, threads[i].first);
      EXPECT_EQ(jobs[i].second, threads[i].second);
    }
  }
}

TEST(Streamer, JobsThatRunAfterTheStreamerIsGoneDoNothing) {
  auto src = std::make_shared<FakeSource>(small_geometry(8, 6), 1);
  TestJobQueue q;
  auto s = make_streamer(src, 9, 8, 0, 0, 16, q.hook());
  std::vector<uint32_t> fb;
  for (uint32_t x = 0; x < 8; ++x) fb.push_back(feedback_pack(0, x, 1));
  const FrameStats st = s->update(fb);
  EXPECT_GT(st.queued, 2u);
  EXPECT_EQ(q.queued(), st.queued);  // no thread of its own: nothing runs until the engine does
  const uint64_t loads_before = src->loads();
  s.reset();
  EXPECT_EQ(q.run_all(), st.queued);  // late jobs run (ASan: no use after free) and do nothing
  EXPECT_EQ(src->loads(), loads_before);
}

TEST(Streamer, AllocatorGetsEveryPageBufferBackAndItsFailuresFallBack) {
  auto src = std::make_shared<FakeSource>(small_geometry(8, 6), 2);
  std::vector<uint32_t> fb;
  for (uint32_t y = 0; y < 6; ++y)
    for (uint32_t x = 0; x < 8; ++x) fb.push_back(feedback_pack(0, x, y));
  CountingAllocator alloc;
  {
    auto s = make_streamer(src, 9, 8, 2, 0, 16, {}, alloc.hook());
    for (int f = 0; f < 30; ++f) {
      s->update(fb);
      auto ups = s->take_uploads();
      for (const PageUpload& u : ups) {
        ASSERT_EQ(u.layers.size(), 2u);
        std::vector<uint8_t> want(src->upload_bytes(1));
        FakeSource::fill(u.page, 1, want);
        EXPECT_TRUE(std::equal(want.begin(), want.end(), u.layers[1].begin()));
      }
      s->wait_idle();
    }
    EXPECT_EQ(s->resident_pages().size(), 65u);
    // Two layers of 65 pages went through the hook; uploads were dropped, so none is live
    // except what the loader still holds (nothing: converged).
    EXPECT_GE(alloc.allocations.load(), 2 * 65);
    EXPECT_EQ(alloc.live_blocks.load(), 0);
  }
  EXPECT_EQ(alloc.live_bytes.load(), 0);
  EXPECT_EQ(alloc.misaligned.load(), 0);
  EXPECT_EQ(alloc.size_mismatches.load(), 0);

  // An allocator that runs dry after the root: pages fail to load (counted, never retried),
  // the root stands in and the streamer stays consistent.
  CountingAllocator dry;
  dry.fail_after = 2;  // the root's two layers
  auto s = make_streamer(src, 9, 8, 2, 0, 16, {}, dry.hook());
  uint32_t errors = 0;
  for (int f = 0; f < 10; ++f) {
    errors += s->update(fb).load_errors;
    s->take_uploads();
    s->wait_idle();
    ASSERT_TRUE(s->check_invariants().ok());
  }
  EXPECT_GT(errors, 0u);
  EXPECT_EQ(s->resident_pages().size(), 1u);
  EXPECT_EQ(s->page_table().entry({0, 3, 3}).level, 3);
  // Not even the root: create fails with a clear error.
  CountingAllocator empty;
  empty.fail_after = 0;
  StreamerOptions o;
  o.allocator = empty.hook();
  auto none = Streamer::create(src, o);
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().code(), ErrorCode::kResourceLimit);
  o.allocator.release = nullptr;
  EXPECT_EQ(Streamer::create(src, o).status().code(), ErrorCode::kInvalidArgument);
  o.allocator = {};
  o.texture_id = kFeedbackMaxTextures;
  EXPECT_EQ(Streamer::create(src, o).status().code(), ErrorCode::kInvalidArgument);
}

TEST(Streamer, ConvergesToEveryRequestedPage) {
  auto src = std::make_shared<FakeSource>(small_geometry(8, 6), 1);
  auto s = make_streamer(src, 9, 8, 2);  // 72 slots for 65 pages
  std::vector<uint32_t> fb;
  for (uint32_t y = 0; y < 6; ++y)
    for (uint32_t x = 0; x < 8; ++x) fb.push_back(feedback_pack(0, x, y));
  int frames = 0;
  for (; frames < 50; ++frames) {
    const FrameStats st = s->update(fb);
    s->take_uploads();
    s->wait_idle();
    if (st.needed > 0 && st.resident_hits == st.needed) break;
  }
  EXPECT_LT(frames, 50);
  EXPECT_EQ(s->resident_pages().size(), 48u + 12u + 4u + 1u);  // every level fits in 64 slots
  const PageTable t = s->page_table();
  for (uint32_t y = 0; y < 6; ++y)
    for (uint32_t x = 0; x < 8; ++x) EXPECT_EQ(t.entry({0, x, y}).level, 0);
  EXPECT_EQ(s->lod_bias(), 0u);
}

TEST(Streamer, ThrashControlRaisesAndLowersBias) {
  auto src = std::make_shared<FakeSource>(small_geometry(16, 16), 1);
  auto s = make_streamer(src, 4, 4, 1);  // 16 slots: level 0 (256 pages) cannot fit
  std::vector<uint32_t> all;
  for (uint32_t y = 0; y < 16; ++y)
    for (uint32_t x = 0; x < 16; ++x) all.push_back(feedback_pack(0, x, y));
  FrameStats st;
  for (int f = 0; f < 20; ++f) {
    st = s->update(all);
    s->take_uploads();
    s->wait_idle();
    ASSERT_TRUE(s->check_invariants().ok());
  }
  // Needed at bias b: 16x16 >> b pages plus ancestors; fits 16 slots from bias 3 (2x2+1x1... ).
  EXPECT_EQ(st.lod_bias, 3u);
  EXPECT_FALSE(st.thrashing);
  EXPECT_LE(st.needed, 16u);
  // A small view afterwards: the bias comes back down.
  std::vector<uint32_t> one = {feedback_pack(0, 3, 3)};
  for (int f = 0; f < 30; ++f) {
    st = s->update(one);
    s->take_uploads();
    s->wait_idle();
  }
  EXPECT_EQ(st.lod_bias, 0u);
  EXPECT_EQ(s->page_table().entry({0, 3, 3}).level, 0);
}

TEST(Streamer, CancelsLoadsNoLongerNeeded) {
  auto src = std::make_shared<FakeSource>(small_geometry(16, 16), 1);
  src->set_delay_us(2000);
  auto s = make_streamer(src, 16, 16, 1, 0, 64);
  std::vector<uint32_t> a;
  for (uint32_t x = 0; x < 16; ++x) a.push_back(feedback_pack(0, x, 0));
  FrameStats st = s->update(a);
  EXPECT_GT(st.queued, 16u);
  st = s->update(std::vector<uint32_t>{});  // the view moved away
  EXPECT_GT(st.cancelled, 0u);
  s->wait_idle();
  st = s->update(std::vector<uint32_t>{});
  EXPECT_EQ(st.mapped, 0u);
  EXPECT_EQ(s->resident_pages().size(), 1u);  // only the root
  EXPECT_LT(src->loads(), 1u + 16u + 8u + 4u + 2u + 1u);
}

TEST(Streamer, UploadByteLimitSpreadsUploads) {
  auto src = std::make_shared<FakeSource>(small_geometry(8, 8), 1);
  StreamerOptions o;
  o.slots_x = o.slots_y = 16;
  o.upload_byte_limit = 3 * slot_bytes(*src);
  auto s = std::move(Streamer::create(src, o)).value();
  EXPECT_EQ(s->take_uploads().size(), 1u);  // the root
  std::vector<uint32_t> fb;
  for (uint32_t y = 0; y < 8; ++y)
    for (uint32_t x = 0; x < 8; ++x) fb.push_back(feedback_pack(0, x, y));
  size_t total = 0;
  for (int f = 0; f < 60; ++f) {
    s->update(fb);
    s->wait_idle();
    const size_t n = s->take_uploads().size();
    EXPECT_LE(n, 3u);
    total += n;
  }
  EXPECT_EQ(total, 64u + 16u + 4u);
}

TEST(Streamer, RejectsBadOptionsAndBudgets) {
  auto src = std::make_shared<FakeSource>(small_geometry(8, 8), 1);
  StreamerOptions o;
  o.slots_x = 0;
  EXPECT_EQ(Streamer::create(src, o).status().code(), ErrorCode::kInvalidArgument);
  o.slots_x = 300;
  EXPECT_EQ(Streamer::create(src, o).status().code(), ErrorCode::kInvalidArgument);
  o = {};
  o.memory_budget_bytes = slot_bytes(*src) * o.max_in_flight;  // staging only, no slot
  EXPECT_EQ(Streamer::create(src, o).status().code(), ErrorCode::kResourceLimit);
  o.threads = 0;
  o.memory_budget_bytes = 0;
  EXPECT_FALSE(Streamer::create(src, o).ok());
  EXPECT_FALSE(Streamer::create(nullptr, StreamerOptions{}).ok());
  PageGeometry huge;
  huge.payload = 120;
  huge.border = 4;
  huge.width = 5000 * 120;
  huge.height = 120;
  EXPECT_EQ(Streamer::create(std::make_shared<FakeSource>(huge, 1), {}).status().code(),
            ErrorCode::kUnsupported);
}

TEST(Streamer, EmptyFileStillGivesAValidTable) {
  // Nothing stored at all (an atlas with no covered texel): the root slot is mapped with
  // zeros so that every table entry is valid and sampling reads defined data.
  auto src =
      std::make_shared<FakeSource>(small_geometry(8, 6), 1, [](const PageId&) { return true; });
  auto s = make_streamer(src, 4, 4, 1);
  const auto ups = s->take_uploads();
  ASSERT_EQ(ups.size(), 1u);
  EXPECT_TRUE(std::all_of(ups[0].layers[0].begin(), ups[0].layers[0].end(),
                          [](uint8_t b) { return b == 0; }));
  const FrameStats st = s->update(std::vector<uint32_t>{feedback_pack(0, 7, 5)});
  EXPECT_EQ(st.needed, 1u);
  EXPECT_EQ(st.queued, 0u);
  EXPECT_EQ(s->page_table().entry({0, 7, 5}).level, 3);
  EXPECT_TRUE(s->check_invariants().ok());
}

TEST(Streamer, UnreadablePagesFallBackToTheirParent) {
  auto src = std::make_shared<FakeSource>(small_geometry(8, 8), 1);
  src->set_failing([](const PageId& id) { return id.level == 0 && id.x == 2; });
  auto s = make_streamer(src, 12, 12, 2);
  std::vector<uint32_t> fb;
  for (uint32_t y = 0; y < 8; ++y)
    for (uint32_t x = 0; x < 8; ++x) fb.push_back(feedback_pack(0, x, y));
  uint32_t errors = 0;
  for (int f = 0; f < 20; ++f) {
    const FrameStats st = s->update(fb);
    errors += st.load_errors;
    s->take_uploads();
    s->wait_idle();
    ASSERT_TRUE(s->check_invariants().ok()) << s->check_invariants().message();
  }
  EXPECT_EQ(errors, 8u);  // each failing page reported once, never retried
  const PageTable t = s->page_table();
  for (uint32_t y = 0; y < 8; ++y) {
    EXPECT_EQ(t.entry({0, 2, y}).level, 1) << y;  // the parent stands in
    EXPECT_EQ(t.entry({0, 3, y}).level, 0) << y;
  }
}

TEST(Streamer, UpdateReturnsWhileLoadsAreStillRunning) {
  auto src = std::make_shared<FakeSource>(small_geometry(8, 8), 1);
  src->set_delay_us(20000);  // 20 ms per page: nothing can finish inside update()
  auto s = make_streamer(src, 12, 12, 1);
  const FrameStats st = s->update(std::vector<uint32_t>{feedback_pack(0, 5, 5)});
  EXPECT_GT(st.queued, 0u);
  EXPECT_EQ(st.mapped, 0u);
  EXPECT_FALSE(s->idle());
  s->wait_idle();
  const FrameStats st2 = s->update(std::vector<uint32_t>{feedback_pack(0, 5, 5)});
  EXPECT_GT(st2.mapped, 0u);
}

// 8 threads hammer one streamer with random frames, prefetches, evictions and upload takes
// while the loader's workers run: 1M operations in all. Run under TSan (see docs/BENCHMARKS.md).
TEST(Streamer, EightThreadTorture) {
  auto src = std::make_shared<FakeSource>(PageGeometry{64, 64, 4, 2}, 1);  // 16x16 pages of 8²
  auto s = make_streamer(src, 6, 6, 3, 0, 12);
  const PageGeometry& g = src->geometry();
  constexpr int kThreads = 8, kOps = 1000000 / kThreads;
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      std::mt19937 rng(100 + t);
      std::vector<uint32_t> fb(4);
      for (int i = 0; i < kOps; ++i) {
        const uint32_t l = rng() % g.level_count();
        const PageId p{l, uint32_t(rng() % g.pages_x(l)), uint32_t(rng() % g.pages_y(l))};
        switch (rng() % 16) {
          case 0:
            for (auto& v : fb) v = feedback_pack(l, rng() % g.pages_x(l), rng() % g.pages_y(l));
            s->update(fb);
            break;
          case 1:
            s->take_uploads();
            break;
          case 2:
            s->request(p);
            break;
          case 3:
            (void)s->lod_bias();
            (void)s->memory_bytes();
            break;
          default:
            s->evict(p);
            break;
        }
      }
    });
  }
  for (auto& t : threads) t.join();
  s->wait_idle();
  s->update(std::vector<uint32_t>{feedback_pack(0, 1, 1)});
  EXPECT_TRUE(s->check_invariants().ok()) << s->check_invariants().message();
  EXPECT_LE(s->resident_pages().size(), 36u);
}

}  // namespace
}  // namespace vt

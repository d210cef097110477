// One mutex guards the queue and the page states; workers and jobs hold it only to pick a page
// and to hand the result back, never while reading or decoding, so request/cancel/collect stay
// cheap. A submitted job owns a reference to the state, so the engine may run it late.
#include "runtime/page_loader.h"

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <unordered_map>

namespace vt {

namespace {

enum class JobState : uint8_t { kQueued, kLoading, kCancelledWhileLoading, kDone };

struct Job {
  PageId id;
  LoadPriority priority;
  uint64_t sequence = 0;
  JobState state = JobState::kQueued;
  LoadedPage result;
};

bool before(const Job& a, const Job& b) {
  if (a.priority.level != b.priority.level) return a.priority.level > b.priority.level;
  if (a.priority.pixels != b.priority.pixels) return a.priority.pixels > b.priority.pixels;
  return a.sequence < b.sequence;
}

}  // namespace

struct PageLoader::Impl {
  std::shared_ptr<const PageSource> source;  // reset by the destructor: late jobs never read
  LoaderOptions options;
  mutable std::mutex mutex;
  std::condition_variable work_cv;
  std::condition_variable idle_cv;
  std::unordered_map<uint64_t, Job> jobs;  // every page queued, loading, done or cancelled
  uint32_t queued = 0, loading = 0;
  uint64_t next_sequence = 0;
  bool stop = false;
  std::vector<std::thread> workers;

  // Loads the best queued page, if any; `lock` is held on entry and on return.
  void load_best(std::unique_lock<std::mutex>& lock) {
    Job* best = nullptr;
    for (auto& [k, job] : jobs)
      if (job.state == JobState::kQueued && (!best || before(job, *best))) best = &job;
    if (!best) return;
    best->state = JobState::kLoading;
    --queued;
    ++loading;
    const PageId id = best->id;
    const uint64_t key = page_key(id);
    lock.unlock();

    LoadedPage page;
    page.id = id;
    const uint32_t layers = source->layer_count();
    page.layers.reserve(layers);
    for (uint32_t l = 0; l < layers && page.status.ok(); ++l) {
      const size_t bytes = source->upload_bytes(l);
      page.layers.emplace_back(bytes, options.allocator);
      page.status = page.layers[l].size() == bytes
                        ? source->load(id, l, page.layers[l])
                        : Error(ErrorCode::kResourceLimit,
                                "page loader: the allocator returned no memory for a page");
    }
    if (!page.status.ok()) page.layers.clear();

    lock.lock();
    --loading;
    auto it = jobs.find(key);
    if (it->second.state == JobState::kCancelledWhileLoading) {
      jobs.erase(it);
    } else {
      it->second.state = JobState::kDone;
      it->second.result = std::move(page);
    }
    if (loading == 0) idle_cv.notify_all();  // the destructor waits for running jobs too
  }

  void run_worker() {
    std::unique_lock lock(mutex);
    for (;;) {
      work_cv.wait(lock, [&] { return stop || queued > 0; });
      if (stop) return;
      load_best(lock);
    }
  }

  // One submitted job: loads one page unless the loader is gone.
  static void run_job(void* token) {
    std::unique_ptr<std::shared_ptr<Impl>> self(static_cast<std::shared_ptr<Impl>*>(token));
    Impl& m = **self;
    std::unique_lock lock(m.mutex);
    if (!m.stop) m.load_best(lock);
  }
};

PageLoader::PageLoader(std::shared_ptr<Impl> impl) : impl_(std::move(impl)) {}

Expected<std::unique_ptr<PageLoader>> PageLoader::create(std::shared_ptr<const PageSource> source,
                                                         const LoaderOptions& options) {
  if (!source) return Error(ErrorCode::kInvalidArgument, "page loader: no page source");
  if (!options.jobs.enabled() && (options.threads == 0 || options.threads > 256))
    return Error(ErrorCode::kInvalidArgument, "page loader: threads must be 1..256");
  if (options.max_in_flight == 0)
    return Error(ErrorCode::kInvalidArgument, "page loader: max_in_flight must be >= 1");
  if (!options.allocator.valid())
    return Error(ErrorCode::kInvalidArgument,
                 "page loader: an allocator needs both allocate and release");
  auto impl = std::make_shared<Impl>();
  impl->source = std::move(source);
  impl->options = options;
  impl->jobs.reserve(options.max_in_flight * 2);
  std::unique_ptr<PageLoader> loader(new PageLoader(impl));
  if (!options.jobs.enabled()) {
    Impl* m = impl.get();
    for (uint32_t t = 0; t < options.threads; ++t)
      m->workers.emplace_back([m] { m->run_worker(); });
  }
  return loader;
}

PageLoader::~PageLoader() {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->stop = true;
  }
  impl_->work_cv.notify_all();
  for (auto& t : impl_->workers) t.join();
  // Jobs already running finish their page; the ones not started find `stop` and return.
  std::unique_lock lock(impl_->mutex);
  impl_->idle_cv.wait(lock, [&] { return impl_->loading == 0; });
  impl_->jobs.clear();
  impl_->source.reset();
}

bool PageLoader::request(const PageId& id, LoadPriority priority) {
  {
    std::lock_guard lock(impl_->mutex);
    Impl& m = *impl_;
    const uint64_t key = page_key(id);
    auto it = m.jobs.find(key);
    if (it != m.jobs.end()) {
      if (it->second.state != JobState::kCancelledWhileLoading) return false;
      // Un-cancel: the load already running is wanted again.
      it->second.state = JobState::kLoading;
      it->second.priority = priority;
      return true;
    }
    if (m.jobs.size() >= m.options.max_in_flight) return false;
    Job job;
    job.id = id;
    job.priority = priority;
    job.sequence = m.next_sequence++;
    m.jobs.emplace(key, std::move(job));
    ++m.queued;
    if (!m.options.jobs.enabled()) {
      m.work_cv.notify_one();
      return true;
    }
  }
  // Outside the lock: a job system may run the job inside submit.
  const JobSystem& js = impl_->options.jobs;
  js.submit(&Impl::run_job, new std::shared_ptr<Impl>(impl_), js.user);
  return true;
}

void PageLoader::reprioritise(const PageId& id, LoadPriority priority) {
  std::lock_guard lock(impl_->mutex);
  auto it = impl_->jobs.find(page_key(id));
  if (it != impl_->jobs.end() && it->second.state == JobState::kQueued)
    it->second.priority = priority;
}

bool PageLoader::cancel(const PageId& id) {
  std::lock_guard lock(impl_->mutex);
  Impl& m = *impl_;
  auto it = m.jobs.find(page_key(id));
  if (it == m.jobs.end()) return false;
  switch (it->second.state) {
    case JobState::kQueued:
      --m.queued;
      m.jobs.erase(it);
      if (m.queued == 0 && m.loading == 0) m.idle_cv.notify_all();
      return true;
    case JobState::kLoading:
      it->second.state = JobState::kCancelledWhileLoading;
      return true;
    case JobState::kDone:
      m.jobs.erase(it);
      return true;
    case JobState::kCancelledWhileLoading:
      return false;
  }
  return false;
}

bool PageLoader::pending(const PageId& id) const {
  std::lock_guard lock(impl_->mutex);
  auto it = impl_->jobs.find(page_key(id));
  return it != impl_->jobs.end() && it->second.state != JobState::kCancelledWhileLoading;
}

void PageLoader::collect(std::vector<LoadedPage>& out) {
  std::vector<Job> done;
  {
    std::lock_guard lock(impl_->mutex);
    for (auto it = impl_->jobs.begin(); it != impl_->jobs.end();) {
      if (it->second.state == JobState::kDone) {
        done.push_back(std::move(it->second));
        it = impl_->jobs.erase(it);
      } else {
        ++it;
      }
    }
  }
  std::sort(done.begin(), done.end(), before);
  for (Job& job : done) out.push_back(std::move(job.result));
}

uint32_t PageLoader::in_flight() const {
  std::lock_guard lock(impl_->mutex);
  // Cancelled loads still running hold a staging buffer too: count them against the budget.
  return uint32_t(impl_->jobs.size());
}

void PageLoader::wait_idle() {
  std::unique_lock lock(impl_->mutex);
  impl_->idle_cv.wait(lock, [&] { return impl_->queued == 0 && impl_->loading == 0; });
}

}  // namespace vt

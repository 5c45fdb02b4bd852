#include "engine/study/sweep_runner.hpp"

#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>

#include "engine/error.hpp"
#include "engine/study/sweep_log.hpp"
#include "io/atomic_file.hpp"

namespace vb {

SweepRunReport run_sweep_cases(const SweepFolder& folder, const SweepGrid& grid,
                               const std::vector<std::string>& case_scenes, const SweepCaseRunner& run_case,
                               const SweepRunOptions& options) {
  require(case_scenes.size() == grid.size(), "one scene text per case expected");
  require(!options.workers.empty(), "a sweep needs at least one worker");
  SweepRunReport report;
  const auto owned = [&](std::size_t i) { return i % std::size_t(options.ranks) == std::size_t(options.rank); };
  folder.remove_leftovers(owned);
  std::vector<std::size_t> pending;
  for (std::size_t i = std::size_t(options.rank); i < grid.size(); i += std::size_t(options.ranks)) {
    ++report.owned;
    const bool finished = folder.is_finished(i);
    if (finished && !(options.retry_failed && folder.read_record(i).status != "ok")) {
      ++report.skipped;
      continue;
    }
    pending.push_back(i);
  }
  const SweepLog log(folder.path("sweep_log.jsonl"));
  log.append({{"event", "start"}, {"rank", options.rank}, {"ranks", options.ranks}, {"workers", options.workers},
              {"cases", report.owned}, {"finished", report.skipped}, {"pending", pending.size()}});

  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;  // guards report, first_error and the progress callback
  std::exception_ptr first_error;
  std::size_t done = report.skipped;
  const std::size_t limit = options.stop_after ? std::min(options.stop_after, pending.size()) : pending.size();

  const auto notify = [&](SweepProgress p) {  // caller holds the mutex
    p.done = done;
    p.total = report.owned;
    if (options.on_progress) options.on_progress(p);
  };

  const auto work = [&](std::size_t worker) {
    while (!stop) {
      const std::size_t k = next++;
      if (k >= limit) return;
      const std::size_t index = pending[k];
      const std::string& device = options.workers[worker];
      try {
        SweepCase c{index, folder.case_id(index), case_scenes[index], folder.make_work_dir(index, options.rank),
                    folder.case_dir(index)};
        write_text_atomically(c.work_dir + "/scene.toml", c.scene_text);
        {
          std::lock_guard lock(mutex);
          SweepProgress started;
          started.index = index;
          started.id = c.id;
          started.worker = worker;
          notify(started);
        }
        log.append({{"event", "case_start"}, {"case", c.id}, {"rank", options.rank}, {"worker", worker}, {"device", device}});
        SweepCaseRecord record{index, "ok", "", options.rank, worker, device, 0};
        const auto start = std::chrono::steady_clock::now();
        try {
          run_case(c, worker);
        } catch (const std::exception& e) {
          record.status = "failed";
          record.error = e.what();
        }
        record.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        nlohmann::json values = nlohmann::json::object();
        const std::vector<std::string> v = grid.values_of(index);
        for (std::size_t p = 0; p < v.size(); ++p) values[grid.parameters()[p].key] = v[p];
        folder.commit(c.work_dir, record, values);
        log.append({{"event", "case_end"}, {"case", c.id}, {"rank", options.rank}, {"worker", worker},
                    {"status", record.status}, {"error", record.error}, {"wall_time_s", record.wall_time_s}});
        std::lock_guard lock(mutex);
        ++report.ran;
        ++done;
        if (record.status != "ok") ++report.failed;
        SweepProgress finished;
        finished.kind = SweepProgress::Kind::Finished;
        finished.index = index;
        finished.id = c.id;
        finished.worker = worker;
        finished.status = record.status;
        finished.error = record.error;
        finished.wall_time_s = record.wall_time_s;
        notify(finished);
      } catch (...) {  // the folder cannot be written: stop every worker and report it
        std::lock_guard lock(mutex);
        if (!first_error) first_error = std::current_exception();
        stop = true;
      }
    }
  };

  if (options.workers.size() == 1) {
    work(0);
  } else {
    std::vector<std::thread> threads;
    for (std::size_t w = 0; w < options.workers.size(); ++w) threads.emplace_back(work, w);
    for (std::thread& t : threads) t.join();
  }
  report.left = report.owned - done;
  log.append({{"event", "stop"}, {"rank", options.rank}, {"ran", report.ran}, {"failed", report.failed},
              {"left", report.left}, {"reason", first_error ? "error" : report.left ? "stop_after" : "done"}});
  if (first_error) std::rethrow_exception(first_error);
  return report;
}

}  // namespace vb

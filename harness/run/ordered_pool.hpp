#pragma once
// Runs jobs 0..n-1 on `width` threads and hands their results back in job order.
//
// For work that waits rather than computes (a child process under callgrind): a thread blocks on its
// child, which TBB's workers must not do. The caller takes results in order, so what it writes from them
// (a journal, a results file) comes out as if the jobs had run one after another.

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

namespace growbench {

template <class T>
class OrderedPool {
 public:
  OrderedPool(std::size_t n, std::size_t width, std::function<T(std::size_t)> run)
      : run_(std::move(run)), results_(n), errors_(n) {
    for (std::size_t t = 0; t < width && t < n; ++t) threads_.emplace_back([this] { work(); });
  }
  // Jobs not yet started are not started; those running are waited for.
  ~OrderedPool() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    for (auto& t : threads_) t.join();
  }
  OrderedPool(const OrderedPool&) = delete;
  OrderedPool& operator=(const OrderedPool&) = delete;

  // Waits for job i and returns its result, or throws what it threw. Each i is taken once.
  T take(std::size_t i) {
    std::unique_lock lock(mutex_);
    done_.wait(lock, [&] { return results_[i].has_value() || errors_[i] != nullptr; });
    if (errors_[i]) std::rethrow_exception(errors_[i]);
    T r = std::move(*results_[i]);
    results_[i].reset();
    return r;
  }

 private:
  void work() {
    while (true) {
      std::size_t i = 0;
      {
        std::lock_guard lock(mutex_);
        if (stop_ || next_ >= results_.size()) return;
        i = next_++;
      }
      std::optional<T> r;
      std::exception_ptr e;
      try {
        r.emplace(run_(i));
      } catch (...) {
        e = std::current_exception();
      }
      {
        std::lock_guard lock(mutex_);
        results_[i] = std::move(r);
        errors_[i] = e;
      }
      done_.notify_all();
    }
  }

  std::function<T(std::size_t)> run_;
  std::mutex mutex_;
  std::condition_variable done_;
  std::vector<std::optional<T>> results_;
  std::vector<std::exception_ptr> errors_;
  std::size_t next_ = 0;
  bool stop_ = false;
  std::vector<std::thread> threads_;
};

}  // namespace growbench

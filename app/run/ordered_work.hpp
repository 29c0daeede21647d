#pragma once
// Two small building blocks of gvio run's threaded pipeline (issue 20). Both keep the order of
// the work fixed, so the results never depend on thread timing:
//  - OrderedWorker runs tasks one after the other, in submission order, on one thread of its own
//    (or inline, when made without a thread): the keyframe work (dense depth, loop features) that
//    only the worker touches until drain();
//  - Prefetcher produces items 0, 1, 2, ... ahead of the consumer on a thread of its own (or on
//    demand, without one): image decoding and rectification before tracking.
// Each has a bounded queue, so a slow consumer (or worker) bounds the memory held. An exception
// thrown on the thread is rethrown to the caller at its next call, in order.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

namespace gvio::run {

class OrderedWorker {
 public:
  // threaded: one worker thread; else submit() runs the task before it returns. capacity: tasks
  // queued before submit() waits (>= 1).
  OrderedWorker(bool threaded, std::size_t capacity);
  ~OrderedWorker();
  OrderedWorker(const OrderedWorker&) = delete;
  OrderedWorker& operator=(const OrderedWorker&) = delete;

  // Queues the task (waits while the queue is full). Rethrows a failure of an earlier task.
  void submit(std::function<void()> task);
  // Waits until every submitted task has run; rethrows the first failure.
  void drain();

 private:
  void loop();
  void rethrowFailure();

  std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::function<void()>> tasks_;
  bool busy_ = false, stop_ = false;
  std::exception_ptr failure_;
  std::thread thread_;  // last: started once the members above exist
};

// Items produce(0), produce(1), ... in order until produce returns nullopt.
template <typename T>
class Prefetcher {
 public:
  using Produce = std::function<std::optional<T>(std::size_t index)>;

  Prefetcher(bool threaded, std::size_t capacity, Produce produce)
      : capacity_(capacity < 1 ? 1 : capacity), produce_(std::move(produce)) {
    if (threaded) thread_ = std::thread([this] { loop(); });
  }
  ~Prefetcher() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    if (thread_.joinable()) thread_.join();
  }
  Prefetcher(const Prefetcher&) = delete;
  Prefetcher& operator=(const Prefetcher&) = delete;

  // The next item, nullopt at the end; rethrows what produce threw for it.
  std::optional<T> next() {
    if (!thread_.joinable()) {
      if (done_) return std::nullopt;
      std::optional<T> item = produce_(next_index_++);
      done_ = !item.has_value();
      return item;
    }
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return !queue_.empty() || done_; });
    if (queue_.empty()) {
      if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
      return std::nullopt;
    }
    std::optional<T> item = std::move(queue_.front());
    queue_.pop_front();
    changed_.notify_all();
    return item;
  }

 private:
  void loop() {
    for (std::size_t index = 0;; ++index) {
      {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [this] { return stop_ || queue_.size() < capacity_; });
        if (stop_) return;
      }
      std::optional<T> item;
      std::exception_ptr failure;
      try {
        item = produce_(index);
      } catch (...) {
        failure = std::current_exception();
      }
      std::lock_guard lock(mutex_);
      if (item) {
        queue_.push_back(std::move(item));
      } else {
        failure_ = failure;  // after the items before it, which next() hands out first
        done_ = true;
      }
      changed_.notify_all();
      if (done_) return;
    }
  }

  std::size_t capacity_;
  Produce produce_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::optional<T>> queue_;
  bool done_ = false, stop_ = false;
  std::exception_ptr failure_;
  std::size_t next_index_ = 0;  // unthreaded only
  std::thread thread_;
};

}  // namespace gvio::run

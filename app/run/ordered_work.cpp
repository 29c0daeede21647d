#include "run/ordered_work.hpp"

namespace gvio::run {

OrderedWorker::OrderedWorker(bool threaded, std::size_t capacity)
    : capacity_(capacity < 1 ? 1 : capacity) {
  if (threaded) thread_ = std::thread([this] { loop(); });
}

OrderedWorker::~OrderedWorker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    tasks_.clear();  // a run that failed elsewhere does not wait for its keyframe work
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void OrderedWorker::rethrowFailure() {
  if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
}

void OrderedWorker::submit(std::function<void()> task) {
  if (!thread_.joinable()) {
    task();
    return;
  }
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return tasks_.size() < capacity_ || failure_; });
  rethrowFailure();
  tasks_.push_back(std::move(task));
  changed_.notify_all();
}

void OrderedWorker::drain() {
  if (!thread_.joinable()) return;
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return (tasks_.empty() && !busy_) || failure_; });
  rethrowFailure();
}

void OrderedWorker::loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return stop_ || !tasks_.empty(); });
    if (stop_) return;
    std::function<void()> task = std::move(tasks_.front());
    tasks_.pop_front();
    busy_ = true;
    lock.unlock();
    std::exception_ptr failure;
    try {
      task();
    } catch (...) {
      failure = std::current_exception();
    }
    lock.lock();
    busy_ = false;
    if (failure) {
      failure_ = failure;
      tasks_.clear();  // later tasks build on this one: none of them runs
    }
    changed_.notify_all();
  }
}

}  // namespace gvio::run

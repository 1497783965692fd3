#pragma once
// A bounded multi-producer multi-consumer queue for the online pipeline's stages. Back-pressure
// is explicit: Push blocks when full (offline, as fast as possible), TryPush refuses (real-time:
// the caller skips), PushDropOldest evicts (viewers). Stop() wakes every waiter; after it, Pop
// drains what is left and then returns nothing.
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>

namespace cslam {

/// Thread-safe FIFO with a capacity; see the file comment for the back-pressure modes.
template <typename T>
class BoundedQueue {
 public:
  explicit BoundedQueue(size_t capacity) : capacity_(capacity == 0 ? 1 : capacity) {}

  /// Blocks while full. Returns false (and drops `item`) once the queue is stopped.
  bool Push(T item) {
    std::unique_lock<std::mutex> lock(mutex_);
    not_full_.wait(lock, [&] { return stopped_ || items_.size() < capacity_; });
    if (stopped_) return false;
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return true;
  }

  /// Never blocks: false when full or stopped.
  bool TryPush(T item) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopped_ || items_.size() >= capacity_) return false;
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return true;
  }

  /// Never blocks: evicts the oldest item when full. Returns how many were evicted (0 or 1).
  int PushDropOldest(T item) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopped_) return 0;
    int dropped = 0;
    if (items_.size() >= capacity_) {
      items_.pop_front();
      dropped = 1;
    }
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return dropped;
  }

  /// Blocks until an item arrives or the queue is stopped and empty (then nullopt).
  std::optional<T> Pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [&] { return stopped_ || !items_.empty(); });
    if (items_.empty()) return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    not_full_.notify_one();
    return item;
  }

  /// Ends the queue: producers are refused, consumers drain the rest.
  void Stop() {
    std::lock_guard<std::mutex> lock(mutex_);
    stopped_ = true;
    not_empty_.notify_all();
    not_full_.notify_all();
  }

  size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }
  size_t capacity() const { return capacity_; }

 private:
  const size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::deque<T> items_;
  bool stopped_ = false;
};

}  // namespace cslam

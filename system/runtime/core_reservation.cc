#include "system/runtime/core_reservation.h"

#include <unistd.h>

namespace cslam {

namespace {

// Failures are ignored on purpose: a thread that keeps its CPUs only costs latency, and the
// run is correct on any CPU.
void SetAffinity(pid_t tid, const cpu_set_t& set) { sched_setaffinity(tid, sizeof(set), &set); }

}  // namespace

CoreReservation::CoreReservation(bool enabled) {
  CPU_ZERO(&allowed_);
  CPU_ZERO(&background_);
  if (!enabled || sched_getaffinity(0, sizeof(allowed_), &allowed_) != 0) return;
  enabled_ = CPU_COUNT(&allowed_) >= 2;
}

CoreReservation::Background::Background(CoreReservation* reservation)
    : reservation_(reservation), tid_(gettid()) {
  if (!reservation_ || !reservation_->enabled_) return;
  const std::lock_guard<std::mutex> lock(reservation_->mutex_);
  reservation_->background_threads_.insert(tid_);
  if (reservation_->reserved_ >= 0) SetAffinity(tid_, reservation_->background_);
}

CoreReservation::Background::~Background() {
  if (!reservation_ || !reservation_->enabled_) return;
  const std::lock_guard<std::mutex> lock(reservation_->mutex_);
  reservation_->background_threads_.erase(tid_);
}

CoreReservation::Scope::Scope(CoreReservation* reservation) : reservation_(reservation) {
  if (reservation_ && reservation_->enabled_) reservation_->Begin();
}

CoreReservation::Scope::~Scope() {
  if (reservation_ && reservation_->enabled_) reservation_->End();
}

void CoreReservation::Begin() {
  const int cpu = sched_getcpu();
  const std::lock_guard<std::mutex> lock(mutex_);
  if (reserved_ >= 0 || cpu < 0 || !CPU_ISSET(cpu, &allowed_)) return;
  reserved_ = cpu;
  background_ = allowed_;
  CPU_CLR(cpu, &background_);
  cpu_set_t mine;
  CPU_ZERO(&mine);
  CPU_SET(cpu, &mine);
  SetAffinity(0, mine);
  // Registered threads hold the mutex to unregister, so none of these ids has exited.
  for (pid_t tid : background_threads_) SetAffinity(tid, background_);
}

void CoreReservation::End() {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (reserved_ < 0) return;
  reserved_ = -1;
  SetAffinity(0, allowed_);
  for (pid_t tid : background_threads_) SetAffinity(tid, allowed_);
}

void CoreReservation::JoinBackground() {
  if (!enabled_) return;
  const std::lock_guard<std::mutex> lock(mutex_);
  if (reserved_ >= 0) SetAffinity(0, background_);
}

int CoreReservation::reserved_cpu() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return reserved_;
}

}  // namespace cslam

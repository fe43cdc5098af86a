// LivePredictionWorker: one thread per prediction job, the newest frame's only
// (LivePredictionWorker.h).
#include "repose/pose/LivePredictionWorker.h"

#include <exception>
#include <utility>

namespace repose {

LivePredictionWorker::~LivePredictionWorker() {
  cancel();
  for (Job& j : stopping_)
    if (j.thread.joinable()) j.thread.join();
}

void LivePredictionWorker::start(std::uint64_t frame, LiveSession::PredictionJob job) {
  if (current_ && current_->frame == frame) return;
  cancel();
  reapStopped();
  Job j;
  j.frame = frame;
  j.shared = std::make_shared<Shared>();
  j.thread = std::thread([shared = j.shared, job = std::move(job)] {
    std::optional<LivePrediction> result;
    std::string error;
    try {
      result = job(&shared->cancel);
    } catch (const std::exception& e) {
      error = e.what();
    } catch (...) {
      error = "unknown error";
    }
    {
      const std::lock_guard<std::mutex> lock(shared->mutex);
      shared->result = std::move(result);
      shared->error = std::move(error);
      shared->done = true;
    }
    shared->finished.notify_all();
  });
  current_ = std::move(j);
}

void LivePredictionWorker::cancel() {
  if (!current_) return;
  current_->shared->cancel = true;
  stopping_.push_back(std::move(*current_));
  current_.reset();
}

void LivePredictionWorker::reapStopped() {
  for (auto it = stopping_.begin(); it != stopping_.end();) {
    bool done;
    {
      const std::lock_guard<std::mutex> lock(it->shared->mutex);
      done = it->shared->done;
    }
    if (done) {
      it->thread.join();
      it = stopping_.erase(it);
    } else {
      ++it;
    }
  }
}

LivePredictionWorker::State LivePredictionWorker::state(std::uint64_t frame) const {
  if (!current_ || current_->frame != frame) return State::None;
  const std::lock_guard<std::mutex> lock(current_->shared->mutex);
  if (!current_->shared->done) return State::Running;
  if (current_->shared->result) return State::Ready;
  return current_->shared->error.empty() ? State::None : State::Failed;
}

std::optional<LivePrediction> LivePredictionWorker::ready(std::uint64_t frame) const {
  if (!current_ || current_->frame != frame) return std::nullopt;
  const std::lock_guard<std::mutex> lock(current_->shared->mutex);
  return current_->shared->done ? current_->shared->result : std::nullopt;
}

std::optional<LivePrediction> LivePredictionWorker::wait(std::uint64_t frame) {
  if (!current_ || current_->frame != frame) return std::nullopt;
  std::unique_lock<std::mutex> lock(current_->shared->mutex);
  current_->shared->finished.wait(lock, [&] { return current_->shared->done; });
  return current_->shared->result;
}

}  // namespace repose

// The live prediction off the caller's thread: a workbench asks for the prediction of the frame at
// hand when a drag ends and keeps its event loop running; the answer is picked up when it is
// ready. One job runs at a time: asking for a newer frame cancels the job of an older one (it
// stops at its next round, LiveSession::predictionJob) and its answer is never given.
#pragma once

#include "repose/pose/LiveSession.h"

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace repose {

class LivePredictionWorker {
 public:
  LivePredictionWorker() = default;
  // Cancels what runs and waits for it (a round of the restoration: tens of milliseconds).
  ~LivePredictionWorker();
  LivePredictionWorker(const LivePredictionWorker&) = delete;
  LivePredictionWorker& operator=(const LivePredictionWorker&) = delete;

  // Starts `job` for frame `frame` (any increasing number the caller gives its frames) unless
  // that frame's job was started already; a job of another frame is cancelled.
  void start(std::uint64_t frame, LiveSession::PredictionJob job);
  // Cancels the running job, if any (a new frame is being solved).
  void cancel();
  enum class State { None, Running, Ready, Failed };
  // Frame `frame`'s job: never started (or cancelled), running, done, or failed (it threw: the
  // caller's own LiveSession::prediction() says why).
  State state(std::uint64_t frame) const;
  // Its prediction when Ready, without waiting.
  std::optional<LivePrediction> ready(std::uint64_t frame) const;
  // Waits for frame `frame`'s job if it runs; its prediction, or nothing (never started,
  // cancelled, failed).
  std::optional<LivePrediction> wait(std::uint64_t frame);

 private:
  struct Shared {
    mutable std::mutex mutex;
    std::condition_variable finished;
    bool done = false;
    std::optional<LivePrediction> result;
    std::string error;
    std::atomic<bool> cancel{false};
  };
  struct Job {
    std::uint64_t frame = 0;
    std::shared_ptr<Shared> shared;
    std::thread thread;
  };
  // Cancelled jobs still finishing their round: joined once done, or at destruction.
  void reapStopped();

  std::optional<Job> current_;
  std::vector<Job> stopping_;
};

}  // namespace repose

// MPI started, waited on and agreed on for the CLI's MPI front ends (MpiSession.h).
#include "MpiSession.h"

#include "../ArgParser.h"

#include "repose/util/Error.h"

#include <chrono>
#include <new>
#include <thread>

namespace repose::cli::mpi {

void await(MPI_Request& request, MPI_Status* status) {
  for (int done = 0;;) {
    MPI_Test(&request, &done, status);
    if (done) return;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

std::string errorText(int code) {
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  return std::string(text, static_cast<std::size_t>(length));
}

Session::Session() {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) {
    int provided = MPI_THREAD_SINGLE;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    owns_ = true;
  }
  MPI_Comm_dup(MPI_COMM_WORLD, &comm_);
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
}

Session::~Session() {
  MPI_Comm_free(&comm_);
  if (owns_) MPI_Finalize();
}

int failureOf(std::string& message) {
  try {
    throw;
  } catch (const Cancelled&) {
    return 2;
  } catch (const UsageError& e) {
    message = e.message;
    return 3;
  } catch (const QuietExit&) {
    message = "a rank failed";
  } catch (const std::bad_alloc&) {
    message = "out of memory";
  } catch (const std::exception& e) {
    message = e.what();
  }
  return 1;
}

void Session::together(const std::function<void()>& step) {
  int kind = 0;
  std::string message;
  try {
    step();
  } catch (...) {
    kind = failureOf(message);
  }
  int mine = kind ? rank_ : size_, first = size_;
  MPI_Request r;
  MPI_Iallreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm_, &r);
  await(r);
  if (first == size_) return;
  const std::string text =
      broadcastFrom(first, rank_ == first ? std::to_string(kind) + message : std::string());
  fail(first, text[0] - '0', text.substr(1));
}

void Session::fail(int first, int kind, const std::string& message) const {
  if (rank_ != 0) throw QuietExit{kind == 2 ? 130 : kind == 3 ? 2 : 1};
  if (kind == 2) throw Cancelled();
  if (kind == 3) throw UsageError{message};
  throw Error(first == 0 ? message : "rank " + std::to_string(first) + ": " + message);
}

std::string Session::broadcastFrom(int root, std::string text) {
  std::int64_t n = static_cast<std::int64_t>(text.size());
  MPI_Request r;
  MPI_Ibcast(&n, 1, MPI_INT64_T, root, comm_, &r);
  await(r);
  text.resize(static_cast<std::size_t>(n));
  MPI_Ibcast(text.data(), static_cast<int>(n), MPI_CHAR, root, comm_, &r);
  await(r);
  return text;
}

}  // namespace repose::cli::mpi

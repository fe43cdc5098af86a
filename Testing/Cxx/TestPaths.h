// Paths tests use: the shared real data beside the checkout, the built executables, and a fresh
// scratch folder per test that is removed afterwards.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace repose::test {

// Whether the tests run under AddressSanitizer (make test-asan with GCC, or clang), whose
// allocator and memory footprint some tests must allow for.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif

inline std::string dataPath(const std::string& relative) {
  return std::string(REPOSE_DATA_DIR) + "/" + relative;
}
inline std::string binPath(const std::string& name) {
  return std::string(REPOSE_BIN_DIR) + "/" + name;
}

// A scratch folder unique to the running test, deleted when the object goes away.
class ScratchDir {
 public:
  // `tag` distinguishes several scratch folders of one test.
  explicit ScratchDir(const std::string& tag = "") {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "repose";
    for (char& c : name)
      if (c == '/') c = '_';
    path_ =
        std::filesystem::temp_directory_path() /
        ("repose-test-" + name + (tag.empty() ? "" : "-" + tag) + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace repose::test

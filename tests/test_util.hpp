#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "scenes/scene.hpp"

namespace growbench::test {

inline std::string shared_mesh(const std::string& name) {
  const std::string p = std::string(GROWBENCH_SHARED_DIR) + "/meshes/" + name;
  if (!std::filesystem::exists(p)) ADD_FAILURE() << "test mesh missing: " << p << " (../shared must sit beside the checkout)";
  return p;
}

// A fresh temporary directory for one test.
inline std::filesystem::path temp_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("growbench_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

inline std::string write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
  return p.string();
}

}  // namespace growbench::test

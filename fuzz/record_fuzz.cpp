// The files the harness writes and reads back (harness/record): the same bytes as a results file, a trial
// record, a baseline, a history file and a journal, each through its typed reader.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_util.hpp"
#include "harness/record/record.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace growbench;
  const std::string path = fuzz::write_input("results.json", data, size);
  fuzz::expect_input_errors([&] { (void)read_results(path); });
  fuzz::expect_input_errors([&] { (void)read_trial_record(path); });
  fuzz::expect_input_errors([&] { (void)read_baseline(path); });
  fuzz::expect_input_errors([&] { (void)read_history_file(path); });
  fuzz::expect_input_errors([&] { (void)read_journal(path); });
  return 0;
}

#include "formats/atomic_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "polycube/errors.h"
#include "support/test_support.h"

namespace polycube {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> entries(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  return names;
}

// Runs f, expecting an OutputError whose message names path.
template <typename F>
void expect_output_error(const std::string& path, F&& f) {
  try {
    f();
    ADD_FAILURE() << "no OutputError for " << path;
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write " + path), std::string::npos) << e.what();
  }
}

TEST(AtomicFile, WritesTheFileAndLeavesNoTemporary) {
  const std::string dir = test::temp_dir("atomic");
  const std::string path = dir + "/out.txt";
  write_text_atomically(path, [](std::ostream& out) { out << "hello\n"; });
  EXPECT_EQ(test::read_file(path), "hello\n");
  EXPECT_EQ(entries(dir), std::vector<std::string>{"out.txt"});
}

TEST(AtomicFile, ReplacesAnExistingFile) {
  const std::string dir = test::temp_dir("atomic");
  const std::string path = dir + "/out.txt";
  test::write_file(path, "old contents that are longer than the new ones");
  write_text_atomically(path, [](std::ostream& out) { out << "new"; });
  EXPECT_EQ(test::read_file(path), "new");
  EXPECT_EQ(entries(dir).size(), 1u);
}

TEST(AtomicFile, TemporaryIsAFreshHiddenFileInTheSameDirectory) {
  const std::string dir = test::temp_dir("atomic");
  const std::string path = dir + "/mesh.ply";
  std::vector<std::string> temps;
  for (int i = 0; i < 2; ++i)
    write_atomically(path, [&](const std::string& temp) {
      temps.push_back(temp);
      EXPECT_TRUE(fs::exists(temp));
      EXPECT_EQ(fs::file_size(temp), 0u);
      std::ofstream(temp) << i;
    });
  ASSERT_EQ(temps.size(), 2u);
  EXPECT_NE(temps[0], temps[1]);
  for (const std::string& temp : temps) {
    EXPECT_EQ(fs::path(temp).parent_path(), fs::path(dir));
    EXPECT_EQ(fs::path(temp).filename().string().rfind(".mesh.ply.tmp-" + std::to_string(::getpid()) + "-", 0), 0u)
        << temp;
  }
  EXPECT_EQ(test::read_file(path), "1");
}

TEST(AtomicFile, ThrowingWriterLeavesNoFileAndPropagatesItsException) {
  const std::string dir = test::temp_dir("atomic");
  const std::string path = dir + "/out.txt";
  EXPECT_THROW(write_atomically(path,
                                [](const std::string& temp) {
                                  std::ofstream(temp) << "half of it";
                                  throw std::logic_error("writer failed");
                                }),
               std::logic_error);
  EXPECT_TRUE(entries(dir).empty());
  EXPECT_THROW(write_text_atomically(path,
                                     [](std::ostream& out) {
                                       out << "half of it";
                                       throw std::runtime_error("writer failed");
                                     }),
               std::runtime_error);
  EXPECT_TRUE(entries(dir).empty());
}

TEST(AtomicFile, ThrowingWriterKeepsThePreviousVersion) {
  const std::string dir = test::temp_dir("atomic");
  const std::string path = dir + "/out.txt";
  test::write_file(path, "previous");
  EXPECT_THROW(write_text_atomically(path,
                                     [](std::ostream& out) {
                                       out << "partial";
                                       throw std::runtime_error("writer failed");
                                     }),
               std::runtime_error);
  EXPECT_EQ(test::read_file(path), "previous");
  EXPECT_EQ(entries(dir).size(), 1u);
}

TEST(AtomicFile, FailedStreamIsAnOutputError) {
  const std::string dir = test::temp_dir("atomic");
  const std::string path = dir + "/out.txt";
  expect_output_error(path, [&] {
    write_text_atomically(path, [](std::ostream& out) {
      out << "something";
      out.setstate(std::ios::badbit);  // as a full disk would
    });
  });
  EXPECT_TRUE(entries(dir).empty());
}

TEST(AtomicFile, MissingDirectoryIsAnOutputError) {
  const std::string path = test::temp_dir("atomic") + "/no/such/dir/out.txt";
  bool called = false;
  expect_output_error(path, [&] { write_atomically(path, [&](const std::string&) { called = true; }); });
  EXPECT_FALSE(called);
  expect_output_error(path, [&] { write_text_atomically(path, [](std::ostream& out) { out << "x"; }); });
}

TEST(AtomicFile, ParentThatIsAFileIsAnOutputError) {
  const std::string dir = test::temp_dir("atomic");
  test::write_file(dir + "/plain", "a file, not a directory");
  const std::string path = dir + "/plain/out.txt";
  expect_output_error(path, [&] { write_text_atomically(path, [](std::ostream& out) { out << "x"; }); });
}

TEST(AtomicFile, DirectoryAsDestinationIsAnOutputError) {
  const std::string dir = test::temp_dir("atomic");
  fs::create_directory(dir + "/sub");
  const std::string path = dir + "/sub";
  expect_output_error(path, [&] { write_text_atomically(path, [](std::ostream& out) { out << "x"; }); });
  EXPECT_TRUE(fs::is_directory(path));
  EXPECT_EQ(entries(dir).size(), 1u);
}

TEST(AtomicFile, UnwritableDirectoryIsAnOutputError) {
  if (::geteuid() == 0) GTEST_SKIP() << "root can write into read-only directories";
  const std::string dir = test::temp_dir("atomic");
  fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
  const std::string path = dir + "/out.txt";
  expect_output_error(path, [&] { write_text_atomically(path, [](std::ostream& out) { out << "x"; }); });
  fs::permissions(dir, fs::perms::owner_all);
  EXPECT_TRUE(entries(dir).empty());
}

TEST(AtomicFile, RelativePathIsWrittenInTheWorkingDirectory) {
  const fs::path previous = fs::current_path();
  const std::string dir = test::temp_dir("atomic");
  fs::current_path(dir);
  write_text_atomically("relative.txt", [](std::ostream& out) { out << "here"; });
  fs::current_path(previous);
  EXPECT_EQ(test::read_file(dir + "/relative.txt"), "here");
  EXPECT_EQ(entries(dir).size(), 1u);
}

TEST(AtomicFile, ConcurrentWritersNeverMixTheirOutputs) {
  const std::string dir = test::temp_dir("atomic");
  const std::string path = dir + "/shared.txt";
  constexpr int writers = 6, rounds = 10;
  // Each writer writes a large file of its own letter: any interleaving would show mixed letters.
  const auto contents = [](int w) { return std::string(200000, static_cast<char>('a' + w)); };
  std::vector<std::thread> threads;
  for (int w = 0; w < writers; ++w)
    threads.emplace_back([&, w] {
      for (int r = 0; r < rounds; ++r) write_text_atomically(path, [&](std::ostream& out) { out << contents(w); });
    });
  for (std::thread& t : threads) t.join();
  const std::string result = test::read_file(path);
  ASSERT_EQ(result.size(), 200000u);
  EXPECT_EQ(result, contents(result[0] - 'a'));
  EXPECT_EQ(entries(dir), std::vector<std::string>{"shared.txt"});
}

}  // namespace
}  // namespace polycube

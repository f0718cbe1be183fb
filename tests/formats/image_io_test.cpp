// Image round trips through every written format family, and the errors users hit: a directory
// that does not exist or cannot be written, files that are missing or not images.
#include "formats/image_io.h"

#include "polycube/errors.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace polycube {
namespace {

namespace fs = std::filesystem;

// Smooth gradients in every channel, values in [0,1], none on an 8-bit step exactly.
Image gradient(int width, int height, int channels) {
  Image image;
  image.width = width;
  image.height = height;
  image.channels = channels;
  image.pixels.resize(static_cast<size_t>(width) * height * channels);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < channels; ++c)
        image.at(x, y, c) = static_cast<float>(
            std::fmod(0.37 * c + (x + 0.3) / width * (c % 2 ? 1.0 : 0.5) + (y + 0.1) / height * 0.4, 1.0));
  return image;
}

// Files left in dir other than the given one (temporaries of the atomic write).
int count_entries(const std::string& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++n;
  return n;
}

TEST(ImageIo, PngRoundTripIsWithinOneStep) {
  const std::string dir = test::temp_dir("image-png");
  const Image original = gradient(37, 23, 4);
  const std::string path = dir + "/gradient.png";
  write_image(path, original);
  const Image read = read_image(path);
  ASSERT_EQ(read.width, 37);
  ASSERT_EQ(read.height, 23);
  ASSERT_EQ(read.channels, 4);
  ASSERT_EQ(read.pixels.size(), original.pixels.size());
  for (size_t i = 0; i < read.pixels.size(); ++i) EXPECT_NEAR(read.pixels[i], original.pixels[i], 1.0 / 255.0);
  // Top row first: the first pixel of the file is the top-left one.
  EXPECT_NEAR(read.at(0, 0, 1), original.at(0, 0, 1), 1.0 / 255.0);
  EXPECT_EQ(count_entries(dir), 1);
  fs::remove_all(dir);
}

TEST(ImageIo, ExrAndTiffRoundTripsAreExact) {
  const std::string dir = test::temp_dir("image-float");
  const Image original = gradient(31, 17, 3);
  for (const std::string name : {"gradient.exr", "gradient.tif"}) {
    SCOPED_TRACE(name);
    write_image(dir + "/" + name, original);
    const Image read = read_image(dir + "/" + name);
    EXPECT_EQ(read.width, original.width);
    EXPECT_EQ(read.height, original.height);
    EXPECT_EQ(read.channels, original.channels);
    EXPECT_EQ(read.pixels, original.pixels);
  }
  EXPECT_EQ(count_entries(dir), 2);
  fs::remove_all(dir);
}

TEST(ImageIo, JpegRoundTripIsClose) {
  const std::string dir = test::temp_dir("image-jpg");
  const Image original = gradient(64, 48, 3);
  write_image(dir + "/gradient.jpg", original);
  const Image read = read_image(dir + "/gradient.jpg");
  ASSERT_EQ(read.pixels.size(), original.pixels.size());
  double error = 0;
  for (size_t i = 0; i < read.pixels.size(); ++i) error += std::abs(double(read.pixels[i]) - original.pixels[i]);
  EXPECT_LT(error / read.pixels.size(), 0.02);  // lossy (and the gradient wraps), but close on average
  fs::remove_all(dir);
}

TEST(ImageIo, OverwritesAnExistingFile) {
  const std::string dir = test::temp_dir("image-overwrite");
  write_image(dir + "/a.png", gradient(8, 8, 3));
  write_image(dir + "/a.png", gradient(5, 4, 1));
  const Image read = read_image(dir + "/a.png");
  EXPECT_EQ(read.width, 5);
  EXPECT_EQ(read.channels, 1);
  EXPECT_EQ(count_entries(dir), 1);
  fs::remove_all(dir);
}

TEST(ImageIo, MissingDirectoryIsOutputError) {
  const std::string dir = test::temp_dir("image-missing");
  EXPECT_THROW(write_image(dir + "/no/such/dir/a.png", gradient(4, 4, 3)), OutputError);
  fs::remove_all(dir);
}

TEST(ImageIo, ReadOnlyDirectoryIsOutputErrorAndLeavesNothing) {
  if (::geteuid() == 0) GTEST_SKIP() << "root can write into read-only directories";
  const std::string dir = test::temp_dir("image-readonly");
  fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
  EXPECT_THROW(write_image(dir + "/a.png", gradient(4, 4, 3)), OutputError);
  fs::permissions(dir, fs::perms::owner_all);
  EXPECT_EQ(count_entries(dir), 0);
  fs::remove_all(dir);
}

TEST(ImageIo, PathThatIsADirectoryIsOutputError) {
  const std::string dir = test::temp_dir("image-isdir");
  fs::create_directory(dir + "/taken.png");
  EXPECT_THROW(write_image(dir + "/taken.png", gradient(4, 4, 3)), OutputError);
  fs::remove_all(dir);
}

TEST(ImageIo, UnknownExtensionAndInconsistentImageAreOutputErrors) {
  const std::string dir = test::temp_dir("image-bad");
  EXPECT_THROW(write_image(dir + "/a.xyz", gradient(4, 4, 3)), OutputError);
  Image broken = gradient(4, 4, 3);
  broken.pixels.pop_back();
  EXPECT_THROW(write_image(dir + "/a.png", broken), OutputError);
  EXPECT_THROW(write_image(dir + "/a.png", Image{}), OutputError);
  EXPECT_EQ(count_entries(dir), 0);
  fs::remove_all(dir);
}

TEST(ImageIo, FailedWriteKeepsThePreviousFile) {
  const std::string dir = test::temp_dir("image-keep");
  write_image(dir + "/a.png", gradient(6, 6, 3));
  Image broken = gradient(4, 4, 3);
  broken.pixels.resize(3);
  EXPECT_THROW(write_image(dir + "/a.png", broken), OutputError);
  EXPECT_EQ(read_image(dir + "/a.png").width, 6);
  EXPECT_EQ(count_entries(dir), 1);
  fs::remove_all(dir);
}

TEST(ImageIo, MissingGarbageAndTruncatedFilesAreInputErrors) {
  const std::string dir = test::temp_dir("image-garbage");
  EXPECT_THROW(read_image(dir + "/missing.png"), InputError);
  {
    std::ofstream out(dir + "/garbage.png", std::ios::binary);
    out << "this is not an image at all\n";
  }
  try {
    read_image(dir + "/garbage.png");
    ADD_FAILURE() << "garbage.png was read";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("garbage.png"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // A real PNG cut in half.
  write_image(dir + "/whole.png", gradient(64, 64, 3));
  const auto size = fs::file_size(dir + "/whole.png");
  fs::copy_file(dir + "/whole.png", dir + "/half.png");
  fs::resize_file(dir + "/half.png", size / 2);
  EXPECT_THROW(read_image(dir + "/half.png"), InputError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace polycube

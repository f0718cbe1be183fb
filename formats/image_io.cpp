#include "formats/image_io.h"

#include "formats/atomic_file.h"
#include "polycube/errors.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace polycube {

namespace {

// The image library's messages may span lines; ours are one line.
std::string one_line(std::string message) {
  std::replace(message.begin(), message.end(), '\n', ' ');
  while (!message.empty() && std::isspace(static_cast<unsigned char>(message.back()))) message.pop_back();
  return message.empty() ? "unknown error" : message;
}

std::string lowercase_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

// Sample type stored in the file: 8-bit for display formats, float where the format has it.
OIIO::TypeDesc file_type(const std::string& path) {
  const std::string ext = lowercase_extension(path);
  if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") return OIIO::TypeDesc::UINT8;
  if (ext == ".exr" || ext == ".tif" || ext == ".tiff") return OIIO::TypeDesc::FLOAT;
  throw OutputError("write_image: unsupported extension '" + ext + "' for " + path +
                    " (use .png, .exr, .tif, .tiff, .jpg or .jpeg)");
}

}  // namespace

void write_image(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 || image.channels <= 0 ||
      image.pixels.size() != static_cast<size_t>(image.width) * image.height * image.channels)
    throw OutputError("write_image: inconsistent image for " + path + ": " + std::to_string(image.width) + "x" +
                      std::to_string(image.height) + "x" + std::to_string(image.channels) + " with " +
                      std::to_string(image.pixels.size()) + " samples");
  const OIIO::TypeDesc type = file_type(path);
  write_atomically(path, [&](const std::string& temp_path) {
    // The plugin is chosen from the final name; the data goes to the temporary one.
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw OutputError("write_image: cannot write " + path + ": " + one_line(OIIO::geterror()));
    OIIO::ImageSpec spec(image.width, image.height, image.channels, type);
    // Samples are stored as given: no premultiplication by alpha on the way out.
    spec.attribute("oiio:UnassociatedAlpha", 1);
    if (!out->open(temp_path, spec))
      throw OutputError("write_image: cannot write " + path + ": " + one_line(out->geterror()));
    const bool written = out->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data());
    const bool closed = out->close();
    if (!written || !closed)
      throw OutputError("write_image: cannot write " + path + ": " + one_line(out->geterror()));
  });
}

Image read_image(const std::string& path) {
  // Samples are returned as stored: no premultiplication by alpha on the way in.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) throw InputError("read_image: cannot read " + path + ": " + one_line(OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  image.channels = spec.nchannels;
  if (image.width <= 0 || image.height <= 0 || image.channels <= 0)
    throw InputError("read_image: " + path + " has no pixels (" + std::to_string(spec.width) + "x" +
                     std::to_string(spec.height) + "x" + std::to_string(spec.nchannels) + ")");
  image.pixels.resize(static_cast<size_t>(image.width) * image.height * image.channels);
  if (!in->read_image(0, 0, 0, image.channels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
    throw InputError("read_image: cannot read " + path + ": " + one_line(in->geterror()));
  in->close();
  return image;
}

}  // namespace polycube

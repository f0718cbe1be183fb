// Reading and writing raster images (texture atlases, checkerboard renders). The image library
// stays inside image_io.cpp; callers see a plain float buffer.
#pragma once

#include <string>
#include <vector>

namespace polycube {

// A raster image with float samples.
//   pixels  width*height*channels values, row-major, top row first, channels interleaved;
//           values in [0,1] for 8-bit formats (clamped on write), unrestricted for float formats;
//           an alpha channel is straight (colour not premultiplied), as stored in the file
struct Image {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;

  // Sample of channel c at column x, row y (row 0 at the top).
  float& at(int x, int y, int c) { return pixels[(static_cast<size_t>(y) * width + x) * channels + c]; }
  float at(int x, int y, int c) const { return pixels[(static_cast<size_t>(y) * width + x) * channels + c]; }
};

// Writes image to path; the format follows the extension: .png (8 bits per channel),
// .exr and .tif/.tiff (32-bit float), .jpg/.jpeg (8 bits, 1 or 3 channels). The file is written
// under a temporary name in the same directory and renamed into place, so a failure leaves no
// partial file and keeps any previous version.
// Throws OutputError("write_image: ...") for an unknown extension, an inconsistent image
// (sizes <= 0 or pixels.size() != width*height*channels) or any write failure, with the image
// library's own message.
void write_image(const std::string& path, const Image& image);

// Reads the first subimage of any format the image library knows, converted to float
// (8-bit values map to [0,1]).
// Throws InputError("read_image: ...") when the file is missing, unreadable or not an image,
// with the image library's own message.
Image read_image(const std::string& path);

}  // namespace polycube

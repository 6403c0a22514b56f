#include "render/image_io.h"

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <stdexcept>

#ifdef CONVOY_RENDER_HAVE_PNG
#include <png.h>
#endif
#ifdef CONVOY_RENDER_HAVE_JPEG
#include <jpeglib.h>
#endif

namespace convoy::render {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& why) {
  throw std::runtime_error(path + ": " + why);
}

struct FileCloser {
  void operator()(FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<FILE, FileCloser>;

File open_file(const std::string& path, const char* mode) {
  File f(std::fopen(path.c_str(), mode));
  if (!f) fail(path, std::strerror(errno));
  return f;
}

#ifdef CONVOY_RENDER_HAVE_PNG
Image load_png(const std::string& path) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    fail(path, std::string("cannot read PNG: ") + png.message);
  }
  png.format = PNG_FORMAT_RGBA;
  Image image{static_cast<int>(png.width), static_cast<int>(png.height), 4, {}};
  image.data.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, image.data.data(), 0, nullptr)) {
    const std::string why = png.message;
    png_image_free(&png);
    fail(path, "cannot decode PNG: " + why);
  }
  return image;
}
#endif

#ifdef CONVOY_RENDER_HAVE_JPEG
struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void jpeg_fail(j_common_ptr info) {
  auto* err = reinterpret_cast<JpegError*>(info->err);
  (*info->err->format_message)(info, err->message);
  std::longjmp(err->jump, 1);
}

// No C++ objects with destructors may live between setjmp and longjmp here, hence the plain
// buffers and the cleanup by hand.
bool decode_jpeg(FILE* file, Image* image, JpegError* err) {
  jpeg_decompress_struct info;
  info.err = jpeg_std_error(&err->mgr);
  err->mgr.error_exit = jpeg_fail;
  if (setjmp(err->jump)) {
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  jpeg_stdio_src(&info, file);
  jpeg_read_header(&info, TRUE);
  info.out_color_space = JCS_EXT_RGBA;
  jpeg_start_decompress(&info);
  image->width = static_cast<int>(info.output_width);
  image->height = static_cast<int>(info.output_height);
  image->channels = 4;
  image->data.resize(static_cast<size_t>(image->width) * image->height * 4);
  while (info.output_scanline < info.output_height) {
    JSAMPROW row =
        image->data.data() + static_cast<size_t>(info.output_scanline) * image->width * 4;
    jpeg_read_scanlines(&info, &row, 1);
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return true;
}

Image load_jpeg(const std::string& path) {
  File f = open_file(path, "rb");
  Image image;
  JpegError err;
  if (!decode_jpeg(f.get(), &image, &err))
    fail(path, std::string("cannot decode JPEG: ") + err.message);
  return image;
}
#endif

}  // namespace

Image load_image_rgba(const std::string& path) {
  unsigned char sig[8] = {};
  {
    File f = open_file(path, "rb");
    if (std::fread(sig, 1, sizeof sig, f.get()) < 3) fail(path, "not an image (too short)");
  }
  if (std::memcmp(sig, "\x89PNG", 4) == 0) {
#ifdef CONVOY_RENDER_HAVE_PNG
    return load_png(path);
#else
    fail(path, "PNG support was not built (libpng not found)");
#endif
  }
  if (sig[0] == 0xFF && sig[1] == 0xD8 && sig[2] == 0xFF) {
#ifdef CONVOY_RENDER_HAVE_JPEG
    return load_jpeg(path);
#else
    fail(path, "JPEG support was not built (libjpeg not found)");
#endif
  }
  fail(path, "unsupported image format (PNG and JPEG are)");
}

void write_ppm(const std::string& path, int width, int height, const uint8_t* rgb) {
  std::ofstream out(path, std::ios::binary);
  if (!out) fail(path, std::string("cannot write: ") + std::strerror(errno));
  out << "P6\n" << width << " " << height << "\n255\n";
  out.write(reinterpret_cast<const char*>(rgb), static_cast<std::streamsize>(width) * height * 3);
  if (!out) fail(path, "write failed");
}

Image read_ppm(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot read: ") + std::strerror(errno));
  std::string magic;
  int width = 0, height = 0, maxval = 0;
  in >> magic;
  // Header fields are separated by whitespace and may be interleaved with # comments.
  auto next_int = [&](int* value) {
    while (in >> std::ws && in.peek() == '#') in.ignore(1 << 20, '\n');
    in >> *value;
  };
  next_int(&width);
  next_int(&height);
  next_int(&maxval);
  if (magic != "P6" || !in || width <= 0 || height <= 0 || maxval != 255) {
    fail(path, "not a binary 8-bit PPM (P6, maxval 255)");
  }
  in.get();  // the single whitespace byte before the pixels
  Image image{width, height, 3, {}};
  image.data.resize(static_cast<size_t>(width) * height * 3);
  in.read(reinterpret_cast<char*>(image.data.data()),
          static_cast<std::streamsize>(image.data.size()));
  if (!in) fail(path, "truncated PPM");
  return image;
}

}  // namespace convoy::render

// image_decode.cpp: PNG (libpng) and JPEG (libjpeg-turbo's TurboJPEG API) to 8-bit RGBA.
//
// libpng reports errors by longjmp. The two functions that call setjmp (pngReadHeader,
// pngReadPixels) hold only plain C data, so the jump skips no destructor; every C++ object
// (the pixel vector, the row table) lives in decodePng, which calls them.
#include "io/image_decode.h"

#include <png.h>
#include <turbojpeg.h>

#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "util/error.h"

namespace nusselt {
namespace {

// Library messages are ASCII, but may quote a chunk name or a marker; keep only printable
// characters so that no byte of the input can reach the terminal raw.
std::string printableAscii(const char* s) {
  std::string out;
  for (; s && *s && out.size() < 300; ++s) {
    unsigned char c = static_cast<unsigned char>(*s);
    if (c >= 0x20 && c < 0x7f) {
      out += char(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    }
  }
  return out;
}

std::string str(std::uint64_t v) { return std::to_string(v); }

void checkPixels(std::uint64_t width, std::uint64_t height, const ImageLimits& limits, const char* format) {
  if (width == 0 || height == 0)
    throw Error(std::string(format) + ": empty image (" + str(width) + " x " + str(height) + ")");
  std::uint64_t pixels = width * height;  // both < 2^32: no overflow
  if (pixels > limits.maxPixels)
    throw Error(std::string(format) + ": " + str(width) + " x " + str(height) + " = " + str(pixels) +
                " pixels exceeds the limit of " + str(limits.maxPixels) + " pixels per image");
}

// ---------------------------------------------------------------------------------------------
// PNG

struct PngSource {
  const std::uint8_t* data;
  std::size_t size;
  std::size_t pos;
  char message[256];
};

void pngRead(png_structp png, png_bytep out, png_size_t n) {
  PngSource* src = static_cast<PngSource*>(png_get_io_ptr(png));
  if (n > src->size - src->pos) png_error(png, "truncated: the data ends inside a chunk");
  std::memcpy(out, src->data + src->pos, n);
  src->pos += n;
}

[[noreturn]] void pngFail(png_structp png, png_const_charp message) {
  PngSource* src = static_cast<PngSource*>(png_get_error_ptr(png));
  std::snprintf(src->message, sizeof src->message, "%s", message ? message : "unknown error");
  png_longjmp(png, 1);
}

void pngWarn(png_structp, png_const_charp) {}  // benign (e.g. a bad ancillary chunk, skipped)

// libpng allocates a chunk at its declared length before reading it, and Debian's build applies
// no chunk cap to ancillary chunks such as iTXt: a 60-byte file declaring a 2 GB iTXt made it
// allocate 2 GB (a fuzz finding; png_set_chunk_malloc_max did not stop it). Every allocation
// libpng needs for an image we use is bounded by a chunk of the file (at most its size) or by a
// row of the image (at most 8 bytes per pixel plus filter and alignment slack) plus the zlib
// state; refuse anything larger. A refused ancillary chunk is skipped with a warning; a refused
// critical one is a "corrupt" error.
struct PngAllocBudget {
  std::size_t fileSize;
  png_infop info = nullptr;  // set once created; the width is known after IHDR
};

png_voidp pngMalloc(png_structp png, png_alloc_size_t n) {
  const PngAllocBudget* budget = static_cast<const PngAllocBudget*>(png_get_mem_ptr(png));
  const png_alloc_size_t width = budget->info ? png_get_image_width(png, budget->info) : 0;
  const png_alloc_size_t cap = budget->fileSize + 16 * width + (png_alloc_size_t(1) << 20);
  return n <= cap ? std::malloc(n) : nullptr;
}

void pngFree(png_structp, png_voidp p) { std::free(p); }

struct PngHeader {
  png_uint_32 width, height;
  int bitDepth, colorType, sourceChannels;
  png_size_t rowBytes;
};

// Reads the chunks up to the image data and sets the transforms to 8-bit RGBA.
bool pngReadHeader(png_structp png, png_infop info, PngHeader* h, std::uint64_t maxPixels) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  int interlace = 0;
  png_get_IHDR(png, info, &h->width, &h->height, &h->bitDepth, &h->colorType, &interlace, nullptr, nullptr);
  const bool trns = png_get_valid(png, info, PNG_INFO_tRNS) != 0;
  switch (h->colorType) {
    case PNG_COLOR_TYPE_GRAY: h->sourceChannels = trns ? 2 : 1; break;
    case PNG_COLOR_TYPE_GRAY_ALPHA: h->sourceChannels = 2; break;
    case PNG_COLOR_TYPE_PALETTE: h->sourceChannels = trns ? 4 : 3; break;
    case PNG_COLOR_TYPE_RGB: h->sourceChannels = trns ? 4 : 3; break;
    default: h->sourceChannels = 4; break;
  }
  // Stop before libpng allocates anything per pixel; the caller reports the size.
  if (std::uint64_t(h->width) * std::uint64_t(h->height) > maxPixels) return true;
  if (h->colorType == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (h->colorType == PNG_COLOR_TYPE_GRAY && h->bitDepth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (trns) png_set_tRNS_to_alpha(png);
  if (h->bitDepth == 16) png_set_scale_16(png);
  if (h->colorType == PNG_COLOR_TYPE_GRAY || h->colorType == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
  png_set_filler(png, 0xff, PNG_FILLER_AFTER);  // no effect when there is an alpha channel
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  h->rowBytes = png_get_rowbytes(png, info);
  return true;
}

bool pngReadPixels(png_structp png, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, nullptr);
  return true;
}

struct PngHandles {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngHandles() { png_destroy_read_struct(&png, info ? &info : nullptr, nullptr); }
};

DecodedImage decodePng(const std::uint8_t* bytes, std::size_t size, const ImageLimits& limits) {
  PngSource src{bytes, size, 0, {0}};
  PngAllocBudget budget{size};
  PngHandles h;
  h.png = png_create_read_struct_2(PNG_LIBPNG_VER_STRING, &src, &pngFail, &pngWarn, &budget, &pngMalloc, &pngFree);
  if (!h.png) throw Error("PNG: out of memory");
  h.info = png_create_info_struct(h.png);
  if (!h.info) throw Error("PNG: out of memory");
  budget.info = h.info;
  png_set_read_fn(h.png, &src, &pngRead);
  // Text and unknown chunks are not needed: do not keep them (nor allocate for them).
  png_set_keep_unknown_chunks(h.png, PNG_HANDLE_CHUNK_NEVER, nullptr, 0);
  PngHeader header{};
  if (!pngReadHeader(h.png, h.info, &header, limits.maxPixels))
    throw Error(std::string("PNG: corrupt: ") + printableAscii(src.message));
  checkPixels(header.width, header.height, limits, "PNG");
  if (header.rowBytes != std::size_t(header.width) * 4)
    throw Error("PNG: unexpected row size " + str(header.rowBytes) + " after conversion to RGBA");
  DecodedImage image;
  image.format = ImageFormat::Png;
  image.width = int(header.width);
  image.height = int(header.height);
  image.sourceChannels = header.sourceChannels;
  image.sourceBits = header.bitDepth;
  image.rgba.resize(std::size_t(header.width) * header.height * 4);
  std::vector<png_bytep> rows(header.height);
  for (std::size_t y = 0; y < rows.size(); ++y) rows[y] = image.rgba.data() + y * header.rowBytes;
  if (!pngReadPixels(h.png, rows.data())) throw Error(std::string("PNG: corrupt: ") + printableAscii(src.message));
  return image;
}

// ---------------------------------------------------------------------------------------------
// JPEG

struct TjHandle {
  tjhandle h = tjInitDecompress();
  ~TjHandle() {
    if (h) tjDestroy(h);
  }
};

DecodedImage decodeJpeg(const std::uint8_t* bytes, std::size_t size, const ImageLimits& limits) {
  TjHandle tj;
  if (!tj.h) throw Error("JPEG: cannot initialise the decoder");
  int width = 0, height = 0, subsamp = 0, colorspace = 0;
  // TurboJPEG takes a non-const pointer in 2.1 but does not write through it.
  unsigned char* data = const_cast<unsigned char*>(bytes);
  if (tjDecompressHeader3(tj.h, data, static_cast<unsigned long>(size), &width, &height, &subsamp, &colorspace) != 0)
    throw Error("JPEG: corrupt: " + printableAscii(tjGetErrorStr2(tj.h)));
  if (colorspace == TJCS_CMYK || colorspace == TJCS_YCCK)
    throw Error("JPEG: CMYK/YCCK images are not supported (convert to RGB)");
  if (width <= 0 || height <= 0) throw Error("JPEG: empty image");
  checkPixels(std::uint64_t(width), std::uint64_t(height), limits, "JPEG");
  DecodedImage image;
  image.format = ImageFormat::Jpeg;
  image.width = width;
  image.height = height;
  image.sourceChannels = colorspace == TJCS_GRAY ? 1 : 3;
  image.sourceBits = 8;
  image.rgba.resize(std::size_t(width) * std::size_t(height) * 4);
  // STOPONWARNING: a truncated or damaged file is an error, not a partly grey image.
  // LIMITSCANS: refuse progressive files with more than 500 scans (a known denial of service).
  const int flags = TJFLAG_STOPONWARNING | TJFLAG_LIMITSCANS | TJFLAG_ACCURATEDCT;
  if (tjDecompress2(tj.h, data, static_cast<unsigned long>(size), image.rgba.data(), width, 0, height, TJPF_RGBA,
                    flags) != 0)
    throw Error("JPEG: corrupt: " + printableAscii(tjGetErrorStr2(tj.h)));
  return image;
}

}  // namespace

const char* imageFormatName(ImageFormat format) { return format == ImageFormat::Png ? "PNG" : "JPEG"; }

std::string describeSignature(const std::uint8_t* bytes, std::size_t size) {
  std::string hex, text;
  for (std::size_t i = 0; i < size && i < 8; ++i) {
    char b[4];
    std::snprintf(b, sizeof b, "%02x", bytes[i]);
    hex += (i ? " " : "") + std::string(b);
    text += (bytes[i] >= 0x20 && bytes[i] < 0x7f && bytes[i] != '"' && bytes[i] != '\\') ? char(bytes[i]) : '.';
  }
  if (size == 0) return "no bytes";
  std::string guess;
  if (size >= 12 && std::memcmp(bytes, "RIFF", 4) == 0 && std::memcmp(bytes + 8, "WEBP", 4) == 0) guess = ": WebP";
  else if (size >= 12 && std::memcmp(bytes, "\xabKTX 20\xbb", 8) == 0) guess = ": KTX2";
  else if (size >= 6 && (std::memcmp(bytes, "GIF87a", 6) == 0 || std::memcmp(bytes, "GIF89a", 6) == 0)) guess = ": GIF";
  else if (size >= 2 && std::memcmp(bytes, "BM", 2) == 0) guess = ": BMP?";
  else if (size >= 4 && std::memcmp(bytes, "DDS ", 4) == 0) guess = ": DDS";
  return "starts with " + hex + " (\"" + text + "\"" + guess + ")";
}

DecodedImage decodeImage(const std::uint8_t* bytes, std::size_t size, const ImageLimits& limits) {
  if (size > limits.maxBytes)
    throw Error("encoded image of " + str(size) + " bytes exceeds the limit of " + str(limits.maxBytes) + " bytes");
  if (size >= 8 && png_sig_cmp(bytes, 0, 8) == 0) return decodePng(bytes, size, limits);
  if (size >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) return decodeJpeg(bytes, size, limits);
  throw Error("not a PNG or JPEG image: " + describeSignature(bytes, size) + "; nusselt decodes PNG and JPEG");
}

}  // namespace nusselt

// image.h: the images nusselt writes and reads. Renders are written as 32-bit float OpenEXR
// (the reference output, bit-exact and with provenance in header attributes) and optionally as a
// tone-mapped 8-bit sRGB PNG for quick viewing. Every writer writes to a temporary file in the
// destination directory and rename()s it into place, so an interrupted or failed write never
// leaves a truncated image where a good one used to be.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace nusselt {

// Linear RGB, float, row-major, top row first.
struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // 3 * width * height
  // Optional per-pixel variance of the mean (3 floats/pixel), written as the channels
  // var.R var.G var.B when non-empty. Empty, or exactly the size of rgb.
  std::vector<float> variance;
  // Optional raw accumulation, for resuming and merging renders (3 floats/pixel each): the sum
  // of the samples (channels sum.R/G/B) and of their squares (sumSq.R/G/B). Present in every
  // render nusselt writes, so that `--resume` and `nusselt merge` continue bit-exactly.
  std::vector<float> sum;
  std::vector<float> sumSq;
};

// Header attributes of an EXR. Names are free-form (e.g. "nusselt/spp") and kept exactly; they
// must be non-empty, unique across the three lists, at most 255 bytes, and must not be one of the
// attributes OpenEXR itself requires ("channels", "compression", "dataWindow", ...).
//
// int64 values: OpenEXR's int attribute is 32-bit. A value inside the int32 range is written as
// an Imf::IntAttribute; a value outside it is written as an Imf::StringAttribute holding its exact
// decimal digits (a double attribute would silently lose precision above 2^53). readExr returns
// each attribute under the type it was stored as, so such a value comes back in `strings`;
// findInt() below accepts both forms.
//
// readExr returns attributes sorted by name (the order OpenEXR stores them in), not in the order
// they were written. Float attributes written by other tools are returned in `doubles`.
struct ImageMetadata {
  std::vector<std::pair<std::string, std::string>> strings;
  std::vector<std::pair<std::string, int64_t>> ints;
  std::vector<std::pair<std::string, double>> doubles;
};

// Lookups in metadata; nullopt when the name is absent (or, for findInt, not an integer).
std::optional<std::string> findString(const ImageMetadata& meta, const std::string& name);
std::optional<int64_t> findInt(const ImageMetadata& meta, const std::string& name);
std::optional<double> findDouble(const ImageMetadata& meta, const std::string& name);

// Limits readExr enforces before allocating, so a corrupt or hostile header cannot make us
// allocate gigabytes. writeExr/writePng enforce the same limits so that we never write a file
// we refuse to read back.
constexpr int kMaxImageSide = 65536;
constexpr int64_t kMaxImagePixels = int64_t(1) << 28;

// Writes a 32-bit float RGB OpenEXR (ZIP compression; plus var.R/G/B when image.variance is
// non-empty) with `meta` as header attributes. The file is written to ".<name>.tmp-<pid>-<n>" in
// the same directory, fsync()ed, and rename()d over `path`. On any failure (bad image size,
// unwritable directory, full disk, ...) the temporary file is removed, an existing `path` is left
// untouched, and nusselt::Error naming `path` and the reason is thrown.
void writeExr(const std::string& path, const Image& image, const ImageMetadata& meta = {});

// Reads an EXR (any scanline or tiled single-part RGB file; channels of any pixel type are
// converted to float) and, if `meta` is given, its string/int/float/double attributes other than
// the ones OpenEXR requires. var.R/G/B are read when all three are present. Throws nusselt::Error
// naming the file on anything wrong: missing, truncated, corrupt, no R/G/B, too large.
Image readExr(const std::string& path, ImageMetadata* meta = nullptr);

// Linear value in [0, 1] (clamped; NaN maps to 0) to an 8-bit sRGB code value using the exact
// piecewise sRGB OETF, rounded to nearest.
uint8_t toSrgb8(float linear);

// Writes a tone-mapped 8-bit sRGB PNG: each channel is scaled by 2^exposureStops, clamped to
// [0, 1] and encoded with toSrgb8. Same temporary file + rename discipline as writeExr.
void writePng(const std::string& path, const Image& image, float exposureStops = 0.0f);

// Error metrics between an image and a reference of equal size (throws nusselt::Error on a size
// mismatch). Means are over all pixels and all three channels; the image's variance is ignored,
// the reference's gives referenceRelMse.
struct ImageDifference {
  double relMse = 0;  // mean of (x - ref)^2 / (ref^2 + 0.01)
  double mse = 0;     // mean of (x - ref)^2
  double meanA = 0, meanB = 0;  // mean of all channels of a and of reference
  double maxAbs = 0;  // max |x - ref|; NaN if any difference is NaN
  // The reference's own noise, where it carries the variance of its mean (var channels: `render
  // --variance`): the mean of var / (ref^2 + 0.01) over the same values as relMse; -1 without.
  // For an image independent of the reference (another seed), E[(x - ref)^2] = E[(x - truth)^2] +
  // var(ref): relMse - referenceRelMse estimates the image's relMSE against the truth (up to the
  // noise of ref^2 in the denominator, of relative order var / ref^2). The var channels are the
  // sample variance over n: the mean's variance for independent samples (`render --rng pcg`);
  // under quasi-Monte Carlo numbers (the default) they overstate it, and so does this.
  double referenceRelMse = -1;
};
ImageDifference compareImages(const Image& a, const Image& reference);
// A map of where the error is (`nusselt diff --map`): each pixel grey at its relative RMS error
// sqrt(mean over its channels of (x - ref)^2 / (ref^2 + 0.01)), the per-pixel root of relMse,
// clamped to [0, 1] (white: 100 % or more; NaN: white). Throws as compareImages.
Image errorMap(const Image& a, const Image& reference);

// The pixels an image's region [x0, x1) x [y0, y1) touches, given as fractions of its width and
// height (0 <= x0 < x1 <= 1, likewise y; at least one pixel): a region of interest that means the
// same part of the picture at any resolution (`nusselt diff --region`). Throws nusselt::Error on
// fractions out of range or in the wrong order; `what` names them in the message.
// Variance channels, where the image has them, are cropped alike.
Image cropImage(const Image& image, double x0, double y0, double x1, double y1, const std::string& what = "region");

}  // namespace nusselt

// The C interface between the drawing layer (plot.cpp) and the OpenImageIO plug-in
// (image_plugin.cpp, built as the MODULE libisolink_images.so). OpenImageIO's Debian build pulls in
// about 280 shared libraries (ffmpeg, GDAL, OpenCV...), which cost every process 170 ms or more in
// the dynamic loader; behind this interface only the commands that draw an image load them, on
// the first Canvas::create (dlopen). Plain C types, so the two sides need no common C++ ABI beyond
// this header; kImagePluginVersion changes when the table does.
#pragma once

#include <cstddef>

extern "C" {

inline constexpr int kImagePluginVersion = 2;

struct IsolinkImageApi {
  int version;  // kImagePluginVersion
  // Box of text drawn at the origin (baseline at y = 0) at size px in the TrueType font file:
  // box = {xbegin, xend, ybegin, yend}. Returns 0 when OIIO cannot measure it (no box).
  int (*text_size)(const char* text, int size, const char* font, int box[4]);
  // Adds the coverage (0..1) of text drawn with its baseline origin at (x, y) to a zeroed w x h
  // single-channel float mask, row-major. Returns 0 on failure.
  int (*render_text)(float* mask, int w, int h, int x, int y, const char* text, int size,
                     const char* font);
  // Encodes w x h 8-bit RGB pixels (row-major, 3 bytes per pixel) as a PNG in memory and hands
  // the bytes to sink(ctx, data, n) (OpenImageIO reports success when a disk fills up under it,
  // so the caller does the checked file write). Returns 0 on success, else copies OIIO's message
  // (NUL-terminated, truncated to errlen) to err.
  int (*encode_png)(int w, int h, const unsigned char* rgb,
                    void (*sink)(void* ctx, const unsigned char* data, size_t n), void* ctx,
                    char* err, size_t errlen);
};

// The plug-in's one exported symbol.
const IsolinkImageApi* isolink_image_api();
using IsolinkImageApiFn = const IsolinkImageApi* (*)();
}

#pragma once
// The C interface between mcslam_dataset (image_codec_loader.cpp) and the image codec module
// (image_codec_module.cpp), which is loaded with dlopen: only C types cross it, and no exception does.
#include <stddef.h>
#include <stdint.h>

// Bumped whenever a signature below changes, so that a stale module is refused instead of called wrongly.
#define MCSLAM_IMAGE_CODEC_ABI_VERSION 2

#define MCSLAM_IMAGE_CODEC_ABI_SYMBOL "mcslam_image_codec_abi_version"
#define MCSLAM_IMAGE_CODEC_READ_SYMBOL "mcslam_image_codec_read_grey"

#ifdef __cplusplus
extern "C" {
#endif

// Called once the image's size is known, before decoding where the format's header tells it (PNG, JPEG): returns
// where to write `height` rows of `width` bytes, *stride bytes apart, or NULL to refuse (the read then fails without
// decoding).
typedef uint8_t* (*mcslam_grey_target_fn)(void* context, int width, int height, ptrdiff_t* stride);

typedef int (*mcslam_image_codec_abi_fn)(void);
// Decodes the image file at `path` as 8-bit grey into the buffer `target` gives. Returns 0 on success; otherwise
// writes a NUL-terminated reason (without the path) into error[error_size].
typedef int (*mcslam_image_codec_read_fn)(const char* path, mcslam_grey_target_fn target, void* context, char* error,
                                          size_t error_size);

#ifdef __cplusplus
}
#endif

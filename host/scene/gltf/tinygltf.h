// tinygltf as the reader uses it: without its image decoding and writing (the reader hands
// images to image/texture_image.h), the same options in every file that includes it.
#pragma once

#ifndef TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE
#endif
#ifndef TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#endif
#include <tiny_gltf.h>

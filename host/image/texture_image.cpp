// PLACEHOLDER until the texture-images branch lands: float images through readImage.
#include "image/texture_image.h"

#include "image/image.h"

namespace pt {

TextureImage readTextureImage(const std::filesystem::path& path) {
  const Image image = readImage(path);
  TextureImage t;
  t.width = image.width;
  t.height = image.height;
  t.channels = 3;
  for (const glm::vec3& p : image.pixels) {
    t.floats.push_back(p.x);
    t.floats.push_back(p.y);
    t.floats.push_back(p.z);
  }
  return t;
}

}  // namespace pt

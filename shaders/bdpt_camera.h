// The camera as a bidirectional method sees it: its importance We, the densities with which it
// samples rays, and a point on its lens sampled towards a point of the scene with the film point
// that point is seen at (pbrt-v4's PerspectiveCamera::We, PDF_We and SampleWi). Shared by the
// CPU reference and the shader; the camera rays themselves are filter.h's.
//
// One difference from pbrt-v4: the importance is normalized over the part of the film that is
// rendered (the crop), not the whole film, because only the crop's pixels start light subpaths.
// pbrt-v4 scales its light-tracing splats and MIS ratios by the film's area over the crop's
// instead (its issue #347); the two are the same where the image is the whole film.
#ifndef PT_BDPT_CAMERA_H
#define PT_BDPT_CAMERA_H

#include "filter.h"
#include "sampling.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

// The area of the rendered pixels' part of the screen window, the plane at unit distance along
// forward (pbrt-v4's A, over the crop).
PT_INLINE float cameraImageArea(PT_IN(Camera) cam) {
  float pixelWidth = 2.0f * cam.tanHalfFovY * cam.aspect / float(cam.filmWidth);
  float pixelHeight = 2.0f * cam.tanHalfFovY / float(cam.filmHeight);
  return pixelWidth * pixelHeight * float(cam.width) * float(cam.height);
}

// The lens's area; 1 for a pinhole (its importance is a delta in position).
PT_INLINE float cameraLensArea(PT_IN(Camera) cam) {
  return cam.lensRadius > 0.0f ? kPi * cam.lensRadius * cam.lensRadius : 1.0f;
}

// Where a ray seen by the camera meets its film: the film point (the whole film's coordinates,
// as generateCameraRay's) of the ray that leaves the lens at lensOffset (from the camera's
// position) along unit direction d, and the cosine of d with the view direction.
// found: the ray comes from the front and its film point lies where the rendered pixels' filters
// reach (their sample bounds).
struct CameraFilmHit {
  bool found;
  vec2 filmPoint;
  float cosTheta;
};

PT_INLINE CameraFilmHit cameraFilmHit(PT_IN(Camera) cam, vec3 lensOffset, vec3 d) {
  CameraFilmHit h = CameraFilmHit(false, vec2(0.0f), dot(d, cam.forward));
  if (!(h.cosTheta > 0.0f)) return h;
  // The pinhole's direction through the same film point: for a thin lens, towards where the ray
  // meets the plane in focus.
  vec3 w = d / h.cosTheta;
  if (cam.lensRadius > 0.0f)
    w = (lensOffset + d * (cam.focalDistance / h.cosTheta)) / cam.focalDistance;
  vec3 q = w - cam.windowCenter;
  float u = dot(q, cam.right) / (cam.tanHalfFovY * cam.aspect);
  float v = dot(q, cam.up) / cam.tanHalfFovY;
  h.filmPoint =
      vec2((u + 1.0f) * 0.5f * float(cam.filmWidth), (1.0f - v) * 0.5f * float(cam.filmHeight));
  // pbrt-v4's Film::SampleBounds: the rendered pixels, widened by the filter's radius less
  // half a pixel, where their camera rays go and where a splat still reaches one of them (the
  // rendered pixels themselves for the box of radius 1/2).
  vec2 margin = vec2(cam.filterRadiusX, cam.filterRadiusY) - 0.5f;
  vec2 low = vec2(float(cam.cropX), float(cam.cropY)) - margin;
  vec2 high = vec2(float(cam.cropX + cam.width), float(cam.cropY + cam.height)) + margin;
  h.found = h.filmPoint.x >= low.x && h.filmPoint.y >= low.y && h.filmPoint.x < high.x &&
            h.filmPoint.y < high.y;
  return h;
}

// The camera's importance for the ray of cameraFilmHit (pbrt-v4's We): 1 / (A lensArea cos^4)
// where it sees the ray, else 0.
PT_INLINE float cameraImportance(PT_IN(Camera) cam, PT_IN(CameraFilmHit) h) {
  if (!h.found) return 0.0f;
  float cos2 = h.cosTheta * h.cosTheta;
  return 1.0f / (cameraImageArea(cam) * cameraLensArea(cam) * cos2 * cos2);
}

// The solid-angle density with which the camera's rays take direction d (pbrt-v4's PDF_We's
// pdfDir): film points uniform over the rendered pixels, 1 / (A cos^3); 0 where it sees none.
// As pbrt-v4's, it is that wherever cameraFilmHit finds the film, in the sample bounds: a
// filter wider than a pixel takes the camera's rays a little past the rendered pixels, which
// the density (used for MIS weights alone) ignores.
PT_INLINE float cameraDirectionPdf(PT_IN(Camera) cam, vec3 lensOffset, vec3 d) {
  CameraFilmHit h = cameraFilmHit(cam, lensOffset, d);
  if (!h.found) return 0.0f;
  return 1.0f / (cameraImageArea(cam) * h.cosTheta * h.cosTheta * h.cosTheta);
}

// A point on the lens sampled towards reference point `ref` (pbrt-v4's SampleWi): uniform on
// the lens's disk (the pinhole itself without a lens), with uLens.
struct CameraWiSample {
  bool found;       // false: the camera does not see ref (behind it, outside the image)
  vec3 pLens;       // the point on the lens
  vec3 lensOffset;  // pLens minus the camera's position
  vec3 wi;          // unit direction from ref towards pLens
  float dist;       // |pLens - ref|
  float pdf;        // solid-angle density of wi at ref: dist^2 / (|cos| lensArea)
  float We;         // the importance of the ray from pLens towards ref
  vec2 filmPoint;   // where it meets the film (the whole film's coordinates)
};

PT_INLINE CameraWiSample sampleCameraWi(PT_IN(Camera) cam, vec3 ref, vec2 uLens) {
  CameraWiSample c;
  c.found = false;
  c.lensOffset = vec3(0.0f);
  if (cam.lensRadius > 0.0f) {
    vec2 lens = cam.lensRadius * sampleConcentricDisk(uLens);
    c.lensOffset = lens.x * cam.right + lens.y * cam.up;
  }
  c.pLens = cam.position + c.lensOffset;
  vec3 toLens = c.pLens - ref;
  float dist2 = dot(toLens, toLens);
  c.dist = sqrt(dist2);
  c.wi = toLens / c.dist;
  c.pdf = 0.0f;
  c.We = 0.0f;
  c.filmPoint = vec2(0.0f);
  if (!(dist2 > 0.0f)) return c;
  CameraFilmHit h = cameraFilmHit(cam, c.lensOffset, -c.wi);
  if (!h.found) return c;
  c.filmPoint = h.filmPoint;
  c.We = cameraImportance(cam, h);
  c.pdf = dist2 / (h.cosTheta * cameraLensArea(cam));
  c.found = true;
  return c;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_BDPT_CAMERA_H

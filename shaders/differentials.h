// Ray differentials and the footprint of a pixel's sample on a surface, as pbrt-v4 defines
// them: the camera's offset rays a pixel away in x and in y (RayDifferential, scaled for the
// samples per pixel), where they meet the tangent plane of a hit and what that is in texture
// coordinates (SurfaceInteraction::ComputeDifferentials), the camera's smallest differentials
// standing in for a ray's own after a bounce that is not specular (Approximate_dp_dxy), and
// the offset rays carried through specular reflection and transmission (SpawnRay). Textures
// filter over the footprint (texture.h); both backends compute it with this code.
#ifndef PT_DIFFERENTIALS_H
#define PT_DIFFERENTIALS_H

#include "sampling.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

// The offset rays of a ray a pixel away on the film in x and in y; present false where the ray
// has none (after a bounce that is not specular, or in a medium).
struct RayDifferential {
  vec3 rxOrigin;
  vec3 rxDirection;
  vec3 ryOrigin;
  vec3 ryDirection;
  bool present;
};

PT_INLINE RayDifferential noRayDifferential() {
  return RayDifferential(vec3(0.0f), vec3(0.0f), vec3(0.0f), vec3(0.0f), false);
}

// The differentials of the camera ray through film point filmPoint that leaves from origin in
// the unit direction `direction`, through the lens at lensOffset from the camera's position
// (zero for a pinhole), as pbrt-v4's PerspectiveCamera::GenerateRayDifferential gives them,
// then scaled by `scale` about the ray (pbrt-v4's ScaleDifferentials).
PT_INLINE RayDifferential cameraRayDifferential(PT_IN(Camera) cam, vec2 filmPoint, vec3 lensOffset,
                                                vec3 origin, vec3 direction, float scale) {
  vec3 wx = cameraFilmVector(cam, filmPoint + vec2(1.0f, 0.0f));
  vec3 wy = cameraFilmVector(cam, filmPoint + vec2(0.0f, 1.0f));
  vec3 dx = normalize(wx);
  vec3 dy = normalize(wy);
  if (cam.lensRadius > 0.0f) {
    // The offset ray through the same lens point towards its film point's point in focus.
    dx = normalize(cam.focalDistance * wx - lensOffset);
    dy = normalize(cam.focalDistance * wy - lensOffset);
  }
  return RayDifferential(origin, direction + (dx - direction) * scale, origin,
                         direction + (dy - direction) * scale, true);
}

// A vector between world and camera space (camera.right, up, forward).
PT_INLINE vec3 worldToCamera(PT_IN(Camera) cam, vec3 v) {
  return vec3(dot(v, cam.right), dot(v, cam.up), dot(v, cam.forward));
}
PT_INLINE vec3 cameraToWorld(PT_IN(Camera) cam, vec3 v) {
  return v.x * cam.right + v.y * cam.up + v.z * cam.forward;
}

// The rotation taking unit vector `from` to unit vector `to` (pbrt-v4's RotateFromTo: two
// reflections through an axis neither lies close to), applied to v, or its inverse.
PT_INLINE vec3 rotateFromTo(vec3 from, vec3 to, vec3 v, bool inverse) {
  vec3 refl = vec3(0.0f, 0.0f, 1.0f);
  if (abs(from.x) < 0.72f && abs(to.x) < 0.72f) {
    refl = vec3(1.0f, 0.0f, 0.0f);
  } else if (abs(from.y) < 0.72f && abs(to.y) < 0.72f) {
    refl = vec3(0.0f, 1.0f, 0.0f);
  }
  vec3 u = refl - from;
  vec3 w = refl - to;
  float uu = dot(u, u);
  float ww = dot(w, w);
  float uw = dot(u, w);
  // r = I - 2/uu u u^T - 2/ww w w^T + 4 uw/(uu ww) w u^T; its inverse is its transpose.
  if (!inverse) {
    return v - (2.0f / uu * dot(u, v)) * u - (2.0f / ww * dot(w, v)) * w +
           (4.0f * uw / (uu * ww) * dot(u, v)) * w;
  }
  return v - (2.0f / uu * dot(u, v)) * u - (2.0f / ww * dot(w, v)) * w +
         (4.0f * uw / (uu * ww) * dot(w, v)) * u;
}

// pbrt-v4's Camera::Approximate_dp_dxy: the change of p across a pixel estimated from the
// camera's smallest differentials (camera space), as if the camera looked straight at p: the
// offset rays from the camera turned to look down p's direction meet the tangent plane (normal
// n), scaled for the samples per pixel.
PT_INLINE void approximateDpdxy(PT_IN(RenderParams) params, vec3 p, vec3 n, PT_OUT(vec3) dpdx,
                                PT_OUT(vec3) dpdy) {
  vec3 pCamera = worldToCamera(params.camera, p - params.camera.position);
  vec3 from = normalize(pCamera);
  vec3 to = vec3(0.0f, 0.0f, 1.0f);
  vec3 pDownZ = rotateFromTo(from, to, pCamera, false);
  vec3 nDownZ = rotateFromTo(from, to, worldToCamera(params.camera, n), false);
  float d = nDownZ.z * pDownZ.z;
  vec3 xDir = to + params.minDirDifferentialX;
  float tx = -(dot(nDownZ, params.minPosDifferentialX) - d) / dot(nDownZ, xDir);
  vec3 yDir = to + params.minDirDifferentialY;
  float ty = -(dot(nDownZ, params.minPosDifferentialY) - d) / dot(nDownZ, yDir);
  vec3 px = params.minPosDifferentialX + tx * xDir;
  vec3 py = params.minPosDifferentialY + ty * yDir;
  float scale = params.differentialScale;
  dpdx = scale * cameraToWorld(params.camera, rotateFromTo(from, to, px - pDownZ, true));
  dpdy = scale * cameraToWorld(params.camera, rotateFromTo(from, to, py - pDownZ, true));
}

// pbrt-v4's ComputeDifferentials' first half: the change of p across a pixel, where the ray's
// offset rays meet the tangent plane at p (normal n), or approximateDpdxy where it has none or
// they run parallel to the plane. Not finite values are made zero by footprintUV.
PT_INLINE void surfaceDpdxy(PT_IN(RenderParams) params, PT_IN(RayDifferential) rd, vec3 p, vec3 n,
                            PT_OUT(vec3) dpdx, PT_OUT(vec3) dpdy) {
  if (rd.present && dot(n, rd.rxDirection) != 0.0f && dot(n, rd.ryDirection) != 0.0f) {
    float d = -dot(n, p);
    float tx = (-dot(n, rd.rxOrigin) - d) / dot(n, rd.rxDirection);
    float ty = (-dot(n, rd.ryOrigin) - d) / dot(n, rd.ryDirection);
    dpdx = rd.rxOrigin + tx * rd.rxDirection - p;
    dpdy = rd.ryOrigin + ty * rd.ryDirection - p;
    return;
  }
  approximateDpdxy(params, p, n, dpdx, dpdy);
}

// A finite value clamped to +-1e8, zero otherwise (pbrt-v4's clamp of the uv derivatives).
PT_INLINE bool isFiniteFloat(float x) {
  return abs(x) <= 3.40282347e38f;
}
PT_INLINE float clampDerivative(float x) {
  return isFiniteFloat(x) ? clamp(x, -1e8f, 1e8f) : 0.0f;
}

// pbrt-v4's ComputeDifferentials' second half: the changes of (u, v) across the pixel, the
// least-squares solution of dp/dx = dp/du du/dx + dp/dv dv/dx (and likewise for y), as
// (du/dx, dv/dx) and (du/dy, dv/dy).
PT_INLINE void footprintUV(vec3 dpdu, vec3 dpdv, vec3 dpdx, vec3 dpdy, PT_OUT(vec2) duvdx,
                           PT_OUT(vec2) duvdy) {
  float ata00 = dot(dpdu, dpdu);
  float ata01 = dot(dpdu, dpdv);
  float ata11 = dot(dpdv, dpdv);
  float invDet = 1.0f / (ata00 * ata11 - ata01 * ata01);
  if (!isFiniteFloat(invDet)) invDet = 0.0f;
  float atb0x = dot(dpdu, dpdx);
  float atb1x = dot(dpdv, dpdx);
  float atb0y = dot(dpdu, dpdy);
  float atb1y = dot(dpdv, dpdy);
  duvdx = vec2(clampDerivative((ata11 * atb0x - ata01 * atb1x) * invDet),
               clampDerivative((ata00 * atb1x - ata01 * atb0x) * invDet));
  duvdy = vec2(clampDerivative((ata11 * atb0y - ata01 * atb1y) * invDet),
               clampDerivative((ata00 * atb1y - ata01 * atb0y) * invDet));
}

// The differentials of the ray leaving p towards wi after a specular reflection (reflection
// true) or transmission of relative index eta, from the arriving ray's (rd, direction -wo), the
// shading normal ns and its changes across the pixel dndx, dndy, and p's dpdx, dpdy (pbrt-v4's
// SurfaceInteraction::SpawnRay, but for the refracted direction's change: see there). None
// where the arriving ray had none, or where they grow beyond 1e8 (pbrt-v4 drops them there).
PT_INLINE RayDifferential specularRayDifferential(PT_IN(RayDifferential) rd, vec3 p, vec3 dpdx,
                                                  vec3 dpdy, vec3 ns, vec3 dndx, vec3 dndy, vec3 wo,
                                                  vec3 wi, bool reflection, float eta) {
  RayDifferential next = noRayDifferential();
  if (!rd.present) return next;
  vec3 n = ns;
  vec3 dwodx = -rd.rxDirection - wo;
  vec3 dwody = -rd.ryDirection - wo;
  next.rxOrigin = p + dpdx;
  next.ryOrigin = p + dpdy;
  if (reflection) {
    float dDNdx = dot(dwodx, n) + dot(wo, dndx);
    float dDNdy = dot(dwody, n) + dot(wo, dndy);
    next.rxDirection = wi - dwodx + 2.0f * (dot(wo, n) * dndx + dDNdx * n);
    next.ryDirection = wi - dwody + 2.0f * (dot(wo, n) * dndy + dDNdy * n);
  } else {
    if (dot(wo, n) < 0.0f) {
      n = -n;
      dndx = -dndx;
      dndy = -dndy;
    }
    float dDNdx = dot(dwodx, n) + dot(wo, dndx);
    float dDNdy = dot(dwody, n) + dot(wo, dndy);
    float mu = dot(wo, n) / eta - abs(dot(wi, n));
    float dmudx = dDNdx * (1.0f / eta + 1.0f / (eta * eta) * dot(wo, n) / dot(wi, n));
    float dmudy = dDNdy * (1.0f / eta + 1.0f / (eta * eta) * dot(wo, n) / dot(wi, n));
    // Snell's law's derivative takes dwo / eta; pbrt-v4 writes eta dwo (docs/textures.md).
    next.rxDirection = wi - dwodx / eta + (mu * dndx + dmudx * n);
    next.ryDirection = wi - dwody / eta + (mu * dndy + dmudy * n);
  }
  next.present = dot(next.rxDirection, next.rxDirection) <= 1e16f &&
                 dot(next.ryDirection, next.ryDirection) <= 1e16f &&
                 dot(next.rxOrigin, next.rxOrigin) <= 1e16f &&
                 dot(next.ryOrigin, next.ryOrigin) <= 1e16f;
  return next;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_DIFFERENTIALS_H

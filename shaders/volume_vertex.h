// What a path does in participating media, written once for the CPU reference and the shader:
// the steps of pbrt-v4's VolPathIntegrator::Li and its SampleLd that path_vertex.h does not
// have. A ray's flight through a medium by delta tracking against the majorants (medium.h),
// with absorption, scattering, null collisions and the medium's emission; the transmittance of
// a shadow ray's segment by ratio tracking (a homogeneous medium's in closed form, as a flight
// through one that only absorbs); light sampling from a point in a medium (the
// Henyey-Greenstein phase function for BSDF); the phase function's sample; emission found and
// light samples weighed by the MIS of the null-scattering path integral (Miller et al. 2019),
// and Russian roulette; the medium a ray enters through a surface.
//
// Spectral MIS over the three channels (pbrt-v4's over its four wavelengths): distances are
// sampled with one channel's majorant, the hero, drawn uniformly per path; rU and rL hold the
// path's densities with each channel as the hero (and those of light sampling), divided by
// the hero's, and every estimate divides by their average. So a chromatic medium (tea,
// coloured glass) is sampled well in every channel, where tracking one fixed channel would
// leave the others with weights that blow up, and the estimate stays unbiased: it is the
// balance heuristic over the three ways the hero could have been chosen. pbrt-v4's
// volpath weighs light sampling and BSDF sampling by the balance heuristic as well (its path
// integrator, and ours without media, by the power heuristic).
//
// What the functions read: what path_vertex.h and medium.h read, and in GLSL
// loadMediumInterface(primitive) (the includer defines it).
#ifndef PT_VOLUME_VERTEX_H
#define PT_VOLUME_VERTEX_H

#include "medium.h"

#ifdef __cplusplus
namespace pt {
inline MediumInterface loadMediumInterface(const PathScene& scene, uint primitive) {
  return scene.mediumInterfaces[primitive];
}
#endif

// Random streams (bsdf.h's makeRandomStream) of the media's sampling: the hero channel
// (drawn at the camera), and the collisions of the flights that start at each scattering
// event and of the shadow rays cast from it.
PT_CONST uint kStreamHeroChannel = 5u;
PT_CONST uint kStreamFlight = 6u;
PT_CONST uint kStreamShadowFlight = 7u;

PT_CONST float kMaxFloat = 3.402823466e38f;

PT_INLINE float average(vec3 v) {
  return (v.x + v.y + v.z) / 3.0f;
}

// An exponentially distributed distance of rate a (the density a exp(-a t)).
PT_INLINE float sampleExponential(float u, float a) {
  return -log(1.0f - u) / a;
}

// ---- The path ----------------------------------------------------------------------------

// What a path carries through media, beyond path_vertex.h's PathState (whose bsdfPdf and
// MIS it replaces with rU and rL).
struct VolumePath {
  PathState path;    // L, beta, etaScale, specularBounce (bsdfPdf: a surface sample's density)
  vec3 rU;           // pbrt-v4's r_u: the path's density with each channel as the hero, over
                     // the density it was sampled with
  vec3 rL;           // r_l: the density of light sampling reaching the path's next vertex,
                     // over the same (times the light's density once one is found)
  uint hero;         // the channel distances are sampled by (0, 1, 2)
  uint medium;       // the medium the ray is in, or kNoMedium
  uint depth;        // scattering events so far (surfaces and media)
  RandomStream rng;  // the flight's collisions, keyed by the next event's dimension
};

// The stream of the flight after `depth` scattering events.
PT_INLINE RandomStream flightStream(PT_SCENE_PARAM uvec2 pixel, uint sampleIndex, uint depth) {
  return makeRandomStream(pixel, sampleIndex, kDimFirstBounce + kDimsPerBounce * depth,
                          PT_PARAMS.seed, kStreamFlight);
}

// A path of camera sample c (in the camera's medium), its hero channel drawn.
PT_INLINE VolumePath startVolumePath(PT_SCENE_PARAM uvec2 pixel, uint sampleIndex,
                                     PT_IN(CameraSample) c) {
  RandomStream heroStream =
      makeRandomStream(pixel, sampleIndex, kDimPixel, PT_PARAMS.seed, kStreamHeroChannel);
  uint hero = min(uint(nextRandom(heroStream) * 3.0f), 2u);
  VolumePath v =
      VolumePath(cameraPathState(PT_SCENE_ARG c), vec3(1.0f), vec3(1.0f), hero,
                 PT_PARAMS.cameraMedium, 0u, flightStream(PT_SCENE_ARG pixel, sampleIndex, 0u));
  v.path.prevP = c.origin;
  return v;
}

// After a scattering event at p: the next flight's random stream, and p as the vertex that
// light sampling's density is measured from.
PT_INLINE void startFlight(PT_SCENE_PARAM PT_INOUT(VolumePath) v, VertexKey key, vec3 p) {
  v.rng = flightStream(PT_SCENE_ARG key.pixel, key.sampleIndex, v.depth);
  v.path.prevP = p;
}

// The medium a ray towards w is in after crossing (or leaving) the surface of triangle
// `primitive` with unit geometric normal ng: the interface's medium on w's side, or `current`
// where the triangle marks no change.
PT_INLINE uint mediumAfter(PT_SCENE_PARAM uint primitive, vec3 ng, vec3 w, uint current) {
  MediumInterface mi = loadMediumInterface(PT_SCENE_ARG primitive);
  if (mi.inside == mi.outside) return current;
  return dot(w, ng) > 0.0f ? mi.outside : mi.inside;
}

// The most interface surfaces (kMaterialInterface) a ray crosses between two scattering
// events, or a shadow ray on its way; a path or shadow ray that would cross more ends there.
PT_CONST uint kMaxInterfaceCrossings = 64u;

// Crossing the interface surface of triangle `index` (tri) at barycentrics b along direction
// d from `medium`: the medium beyond, and in `origin` where the ray goes on from (offset to
// the far side).
PT_INLINE uint crossInterface(PT_SCENE_PARAM uint index, PT_IN(Triangle) tri, vec3 b, vec3 d,
                              uint medium, PT_OUT(vec3) origin) {
  TriangleShading shading = triangleShadingAt(PT_SCENE_ARG index, tri);
  vec3 p = b.x * tri.v0 + b.y * tri.v1 + b.z * tri.v2;
  vec3 side = dot(shading.normal, d) > 0.0f ? shading.normal : -shading.normal;
  origin = offsetRayOrigin(p, side, shading.magnitude);
  return mediumAfter(PT_SCENE_ARG tri.primitive, shading.normal, d, medium);
}

// ---- Tentative collisions -------------------------------------------------------------------

// The tentative collisions of a ray with a medium: distances sampled at the hero channel's
// majorant, segment by segment of the majorant walk (pbrt-v4's SampleT_maj, as an iterator
// rather than a callback). Between collisions, T gathers the majorant's transmittance in
// every channel.
struct CollisionWalk {
  MajorantWalk walk;
  MajorantSegment seg;  // the segment under way
  bool inSegment;       // seg is under way
  float tMin;           // where the next distance is measured from
  vec3 T;               // the majorant's transmittance since the last collision (or the start)
};

PT_INLINE CollisionWalk startCollisionWalk(PT_IN(Medium) m, vec3 o, vec3 d, float tMax) {
  return CollisionWalk(startMajorantWalk(m, o, d, tMax), MajorantSegment(0.0f, 0.0f, vec3(0.0f)),
                       false, 0.0f, vec3(1.0f));
}

// The next tentative collision, at t along the ray (c.seg.sigmaMaj the majorant there, c.T
// the transmittance since the last); false once the ray's range is crossed, c.T then holding
// the transmittance of its rest. A segment where the hero's majorant is zero is crossed whole.
PT_INLINE bool nextCollision(PT_SCENE_PARAM PT_INOUT(CollisionWalk) c, uint h,
                             PT_INOUT(RandomStream) rng, PT_OUT(float) t) {
  for (;;) {
    if (!c.inSegment) {
      if (!nextMajorantSegment(PT_SCENE_ARG c.walk, c.seg)) return false;
      c.tMin = c.seg.tMin;
      if (c.seg.sigmaMaj[h] == 0.0f) {
        c.T *= exp(-min(c.seg.tMax - c.seg.tMin, kMaxFloat) * c.seg.sigmaMaj);
        continue;
      }
      c.inSegment = true;
    }
    PT_MEDIUM_LOOP_TICK();
    t = c.tMin + sampleExponential(nextRandom(rng), c.seg.sigmaMaj[h]);
    if (t < c.seg.tMax) {
      c.T *= exp(-(t - c.tMin) * c.seg.sigmaMaj);
      c.tMin = t;
      return true;
    }
    c.T *= exp(-min(c.seg.tMax - c.tMin, kMaxFloat) * c.seg.sigmaMaj);
    c.inSegment = false;
  }
}

// ---- Homogeneous media in closed form -----------------------------------------------------

// A homogeneous medium's transmittance exp(-sigma_t t) over a ray's length t (infinite where
// the ray leaves the scene: then zero, or one in a medium that neither absorbs nor scatters).
PT_INLINE vec3 homogeneousTransmittance(PT_IN(Medium) m, float t) {
  return exp(-min(t, kMaxFloat) * (m.sigmaA + m.sigmaS));
}

// A homogeneous medium in which nothing happens along a ray but absorption (no scattering, no
// emission): a flight through it passes with the transmittance's weight, in every channel.
PT_INLINE bool onlyAbsorbs(PT_IN(Medium) m) {
  return PT_HAS_MEDIUM(m, kMediumHomogeneous) && m.emissive == 0u && maxComponent(m.sigmaS) == 0.0f;
}

// ---- Delta tracking of a flight ------------------------------------------------------------

// How far along its unit ray a flight through homogeneous medium m, which scatters, makes its
// first tentative collision: trackFlight below draws the same two numbers from v.rng (the
// event's, then the distance's), so a surface beyond this distance cannot end the flight.
// kMaxFloat where that is not known ahead (another medium, one that only absorbs, a hero
// channel without extinction). The CPU searches a flight's surface only up to there.
PT_INLINE float firstCollisionAhead(PT_IN(Medium) m, PT_IN(VolumePath) v) {
  float sigmaT = (m.sigmaA + m.sigmaS)[v.hero];
  if (!PT_HAS_MEDIUM(m, kMediumHomogeneous) || onlyAbsorbs(m) || !(sigmaT > 0.0f)) {
    return kMaxFloat;
  }
  RandomStream ahead = v.rng;
  nextRandom(ahead);
  return sampleExponential(nextRandom(ahead), sigmaT);
}

PT_CONST uint kFlightPassed = 0u;     // the ray reached tMax (the surface, or nothing)
PT_CONST uint kFlightScattered = 1u;  // it scattered at `p`
PT_CONST uint kFlightEnded = 2u;      // absorbed, or nothing left to carry

// The path's ray o + t d (d unit) through its medium from t = 0 to tMax (the surface it
// found, or infinity): tentative collisions at the majorant's rate, each an absorption, a real
// scattering or a null collision with the probabilities of the hero channel's coefficients
// (pbrt-v4's SampleT_maj and the events of its volpath), the medium's emission added at each.
// Updates beta, rU and rL; on kFlightScattered, p is the point and g the phase function's
// asymmetry there. Through a medium that only absorbs (onlyAbsorbs) the flight passes with
// beta times the transmittance, where pbrt-v4's delta tracking would end the path with the
// probability of absorption: the same mean, without that noise. Its draws from v.rng are
// firstCollisionAhead's: change both together.
PT_INLINE uint trackFlight(PT_SCENE_PARAM PT_INOUT(VolumePath) v, vec3 o, vec3 d, float tMax,
                           PT_OUT(vec3) p, PT_OUT(float) g) {
  uint h = v.hero;
  Medium m = loadMedium(PT_SCENE_ARG v.medium);
  g = m.g;
  p = o;
  if (onlyAbsorbs(m)) {
    v.path.beta *= homogeneousTransmittance(m, tMax);
    return maxComponent(v.path.beta) > 0.0f ? kFlightPassed : kFlightEnded;
  }
  CollisionWalk c = startCollisionWalk(m, o, d, tMax);
  float uMode = nextRandom(v.rng);
  float t;
  while (nextCollision(PT_SCENE_ARG c, h, v.rng, t)) {
    vec3 sigmaMaj = c.seg.sigmaMaj;
    vec3 T = c.T;
    p = o + t * d;
    MediumProperties mp = mediumPropertiesAt(PT_SCENE_ARG m, p);
    // The medium's emission, weighed by the densities of reaching this point.
    if (m.emissive != 0u && v.depth < PT_PARAMS.maxDepth && maxComponent(mp.Le) > 0.0f) {
      float pdf = sigmaMaj[h] * T[h];
      vec3 rE = v.rU * sigmaMaj * T / pdf;
      if (maxComponent(rE) > 0.0f) {
        v.path.L += (v.path.beta * T / pdf) * mp.sigmaA * mp.Le / average(rE);
      }
    }
    // Which event: absorption, scattering or a null collision, by the hero's coefficients.
    float pAbsorb = mp.sigmaA[h] / sigmaMaj[h];
    float pScatter = mp.sigmaS[h] / sigmaMaj[h];
    float pNull = max(0.0f, 1.0f - pAbsorb - pScatter);
    float up = uMode * (pAbsorb + pScatter + pNull);
    uMode = nextRandom(v.rng);
    if (up < pAbsorb) return kFlightEnded;
    if (up < pAbsorb + pScatter) {
      float pdf = T[h] * mp.sigmaS[h];
      v.path.beta *= T * mp.sigmaS / pdf;
      v.rU *= T * mp.sigmaS / pdf;
      return maxComponent(v.path.beta) > 0.0f && maxComponent(v.rU) > 0.0f ? kFlightScattered
                                                                           : kFlightEnded;
    }
    vec3 sigmaN = max(sigmaMaj - mp.sigmaA - mp.sigmaS, vec3(0.0f));
    float pdf = T[h] * sigmaN[h];
    if (pdf == 0.0f) return kFlightEnded;
    v.path.beta *= T * sigmaN / pdf;
    v.rU *= T * sigmaN / pdf;
    v.rL *= T * sigmaMaj / pdf;
    if (!(maxComponent(v.path.beta) > 0.0f) || !(maxComponent(v.rU) > 0.0f)) {
      return kFlightEnded;
    }
    c.T = vec3(1.0f);
  }
  // No collision left: the majorant's transmittance over the probability of passing.
  vec3 T = c.T;
  if (!(T[h] > 0.0f)) return kFlightEnded;
  v.path.beta *= T / T[h];
  v.rU *= T / T[h];
  v.rL *= T / T[h];
  return kFlightPassed;
}

// ---- Shadow rays through media -------------------------------------------------------------

// What a shadow ray gathers over its segments: the transmittance estimate and the densities
// of the two strategies along it (pbrt-v4's T_ray, r_u, r_l in SampleLd).
struct ShadowTransmittance {
  vec3 T;
  vec3 rU;
  vec3 rL;
  RandomStream rng;
};

PT_INLINE ShadowTransmittance startShadowTransmittance(PT_SCENE_PARAM VertexKey key) {
  return ShadowTransmittance(
      vec3(1.0f), vec3(1.0f), vec3(1.0f),
      makeRandomStream(key.pixel, key.sampleIndex, key.dim, PT_PARAMS.seed, kStreamShadowFlight));
}

// Ratio tracking over the shadow ray's segment o + t d (d unit), t in [0, tMax), in `medium`
// (the hero's majorant), with pbrt-v4's roulette where the estimate falls below 0.05. False
// when the transmittance has become zero. A homogeneous medium's segment takes its
// transmittance in closed form: there the majorant is sigma_t, and ratio tracking (pbrt-v4's
// for every medium) would estimate it by zero or one. No choice depends on the hero there, so
// rU and rL are unchanged.
PT_INLINE bool trackShadowSegment(PT_SCENE_PARAM PT_INOUT(ShadowTransmittance) tr, uint medium,
                                  uint h, vec3 o, vec3 d, float tMax) {
  Medium m = loadMedium(PT_SCENE_ARG medium);
  if (PT_HAS_MEDIUM(m, kMediumHomogeneous)) {
    tr.T *= homogeneousTransmittance(m, tMax);
    return maxComponent(tr.T) > 0.0f;
  }
  CollisionWalk c = startCollisionWalk(m, o, d, tMax);
  float t;
  while (nextCollision(PT_SCENE_ARG c, h, tr.rng, t)) {
    vec3 sigmaMaj = c.seg.sigmaMaj;
    vec3 T = c.T;
    MediumProperties mp = mediumPropertiesAt(PT_SCENE_ARG m, o + t * d);
    vec3 sigmaN = max(sigmaMaj - mp.sigmaA - mp.sigmaS, vec3(0.0f));
    float pdf = T[h] * sigmaMaj[h];
    tr.T *= T * sigmaN / pdf;
    tr.rL *= T * sigmaMaj / pdf;
    tr.rU *= T * sigmaN / pdf;
    // Roulette where little is left to carry.
    vec3 estimate = tr.T / average(tr.rL + tr.rU);
    if (maxComponent(estimate) < 0.05f) {
      if (nextRandom(tr.rng) < 0.75f) {
        tr.T = vec3(0.0f);
      } else {
        tr.T /= 0.25f;
      }
    }
    if (!(maxComponent(tr.T) > 0.0f)) return false;
    c.T = vec3(1.0f);
  }
  vec3 T = c.T;
  if (!(T[h] > 0.0f)) {
    tr.T = vec3(0.0f);
    return false;
  }
  tr.T *= T / T[h];
  tr.rL *= T / T[h];
  tr.rU *= T / T[h];
  return maxComponent(tr.T) > 0.0f;
}

// ---- Light sampling and emission found, weighed over the channels --------------------------

// A point of a medium as light sampling (path_vertex.h's sampleLightAt) sees it: scattering by
// the phase function of asymmetry g, seen from direction wo, with no ray offset.
PT_INLINE SurfacePoint mediumPoint(vec3 p, vec3 wo, float g) {
  SurfacePoint s;
  s.material.g = g;
  s.p = p;
  s.ng = wo;
  s.ns = wo;
  s.n = wo;
  s.wo = wo;
  s.cosOut = 1.0f;
  s.magnitude = 0.0f;  // the shadow ray leaves p itself
  s.area = 0.0f;
  s.shadingNormals = true;
  s.scatter = kScatterPhase;
  return s;
}

// The contribution of light sample ls whose shadow ray carried `tr`, where the path's vertex
// scatters with value f (times its cosine) and samples the light's direction with density
// scatterPdf; weighed against that sampling by the balance heuristic over all three heroes
// (not for delta lights, nor with light sampling alone).
PT_INLINE vec3 volumeLightContribution(PT_SCENE_PARAM PT_IN(VolumePath) v, vec3 f, float scatterPdf,
                                       PT_IN(LightSample) ls, PT_IN(ShadowTransmittance) tr) {
  vec3 rL = v.rU * tr.rL * ls.lightPdf;
  vec3 rU = v.rU * tr.rU * scatterPdf;
  vec3 c = v.path.beta * f * tr.T * ls.Li;
  if (ls.delta || !misOn(PT_SCENE_ONLY)) return c / average(rL);
  return c / average(rL + rU);
}

// Emission found on a surface (triangle tri, shading point s) by the path's ray: at full
// weight after a specular bounce or from the camera, else weighed against light sampling from
// the last scattering vertex.
PT_INLINE void addVolumeEmissionFound(PT_SCENE_PARAM PT_INOUT(VolumePath) v, PT_IN(Triangle) tri,
                                      PT_IN(SurfacePoint) s) {
  float cosEmit = emissionCosine(s);
  if (tri.emitter == kNoEmitter || !(cosEmit > 0.0f)) return;
  float denominator = average(v.rU);
  if (!v.path.specularBounce) {
    if (!bsdfEmissionOn(PT_SCENE_ONLY)) return;
    if (misOn(PT_SCENE_ONLY)) {
      float lightPdf = emitterPdfFound(PT_SCENE_ARG tri, s, cosEmit, distance(v.path.prevP, s.p),
                                       v.path.prevP, v.path);
      denominator = average(v.rU + v.rL * lightPdf);
    }
  }
  v.path.L += v.path.beta * s.material.emission / denominator;
}

// The infinite light's radiance seen by a ray that leaves the scene along `direction`,
// weighed as emission found on a surface is.
PT_INLINE void addVolumeEnvironmentFound(PT_SCENE_PARAM PT_INOUT(VolumePath) v, vec3 direction) {
#ifndef PT_NO_BSDF_MATERIALS
  if (!PT_HAS_ENVIRONMENT || PT_PARAMS.environmentEmitter == kNoEmitter) return;
  EnvironmentFound e = environmentFound(PT_SCENE_ARG direction);
  float denominator = average(v.rU);
  if (!v.path.specularBounce) {
    if (!bsdfEmissionOn(PT_SCENE_ONLY)) return;
    if (misOn(PT_SCENE_ONLY)) denominator = average(v.rU + v.rL * e.lightPdf);
  }
  v.path.L += v.path.beta * e.Le / denominator;
#endif
}

// ---- Scattering ---------------------------------------------------------------------------

// The phase function's sample at a point of a medium: the next direction (from wo, the
// direction back along the ray), its density as the next vertex's rL. False: none.
PT_INLINE bool scatterInMedium(PT_INOUT(VolumePath) v, vec3 wo, float g, vec2 u, PT_OUT(vec3) wi) {
  float pdf;
  wi = sampleHenyeyGreenstein(wo, g, u, pdf);
  if (!(pdf > 0.0f)) return false;
  // The phase function's value over its density is one: beta is unchanged.
  v.rL = v.rU / pdf;
  v.path.prevN = vec3(0.0f);  // a point of a medium: the light BVH weighs no surface
  v.path.specularBounce = false;
  v.path.rd.present = false;
  return true;
}

// After a BSDF sample at a surface (path_vertex.h's sampleBsdfAt, which set bsdfPdf): light
// sampling's relative density for the next vertex.
PT_INLINE void afterSurfaceScatter(PT_INOUT(VolumePath) v) {
  if (!v.path.specularBounce) v.rL = v.rU / v.path.bsdfPdf;
}

// Russian roulette after a surface's scattering event (pbrt-v4's volpath does none after a
// medium's), by beta times etaScale over the average density ratio.
PT_INLINE bool survivesVolumeRoulette(PT_SCENE_PARAM PT_INOUT(VolumePath) v, float u) {
  if (!rouletteOn(PT_SCENE_ONLY) || v.depth < PT_PARAMS.rrStartDepth) return true;
  float q = max(0.0f, 1.0f - maxComponent(v.path.beta * v.path.etaScale / average(v.rU)));
  if (u < q) return false;
  v.path.beta /= 1.0f - q;
  return true;
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_VOLUME_VERTEX_H

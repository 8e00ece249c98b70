// The connection strategies of bidirectional path tracing and their MIS weights (pbrt-v4's
// ConnectBDPT and MISWeight; book 3rd edition 16.3.3 and 16.3.4), over bdpt_vertex.h's
// subpaths, written once for the CPU reference and the shader. Strategy (s, t) joins the first
// s vertices of the light subpath to the first t of the camera subpath: s = 0 takes the camera
// subpath as a whole path (its last vertex emits), t = 1 samples a point on the lens towards
// a light subpath's vertex (light tracing: a splat on the film), s = 1 samples a point on a light
// towards a camera subpath's vertex (next-event estimation), the rest join two vertices with a
// segment. The backend traces the segment's shadow ray; the MIS weight follows.
//
// The weight is the power heuristic (exponent 2) over every strategy that could have sampled
// the same path, computed by pbrt-v4's recursion over the ratios of each vertex's two
// densities; pbrt-v4 uses the balance heuristic (exponent 1) there. Delta vertices (specular
// bounces, delta lights) are skipped as pbrt-v4 skips them, and their zero densities count as 1.
//
// Where a vertex index would be below 0 for a strategy that does not read it (t - 2 for t = 1,
// say), it is clamped to 0 (max(t, 2u) - 2u): lavapipe runs both sides of a branch and both
// operands of a selection, and would read outside the subpath's array.
#ifndef PT_BDPT_CONNECT_H
#define PT_BDPT_CONNECT_H

#include "bdpt_camera.h"
#include "bdpt_vertex.h"
#include "lights.h"
#include "sampling.h"
#include "shared_types.h"

#ifdef __cplusplus
namespace pt {
#endif

#ifndef __cplusplus
// The shader's two subpaths (PT_BDPT_PATHS_PARAM): one pixel sample's, per invocation.
BdptPath lightPath;
BdptPath cameraPath;
#endif

// One connection before its shadow ray: the path's contribution without its MIS weight, given
// that the segment from `from` to `to` (t in [0, 1)) is clear where `visibility` asks.
struct BdptConnection {
  bool found;       // false: it contributes nothing (no shadow ray to trace)
  vec3 L;           // the unweighted contribution
  bool visibility;  // the segment needs a shadow ray (all but s = 0)
  vec3 from;
  vec3 to;
  BdptVertex sampled;  // s = 1: the light's point; t = 1: the lens point
  vec2 filmPoint;      // t = 1: where the splat lands (the whole film's coordinates)
};

// Where a segment from vertex v towards unit direction w starts: off a surface on the side w
// leaves from, at a point or lens itself.
PT_INLINE vec3 bdptSegmentEnd(PT_IN(BdptVertex) v, vec3 w) {
  if (!bdptOnSurface(v) || bdptIsInfiniteLight(v)) return v.p;
  return offsetRayOrigin(v.p, dot(v.ng, w) > 0.0f ? v.ng : -v.ng, v.s.magnitude);
}

// The geometric term between two vertices at distance sqrt(dist2) along unit d, the cosines at
// those on a surface about their shading normals (pbrt-v4's G, without the transmittance).
PT_INLINE float bdptGeometry(PT_IN(BdptVertex) a, PT_IN(BdptVertex) b, vec3 d, float dist2) {
  float g = 1.0f / dist2;
  if (bdptOnSurface(a)) g *= abs(dot(a.ns, d));
  if (bdptOnSurface(b)) g *= abs(dot(b.ns, d));
  return g;
}

PT_INLINE BdptConnection noBdptConnection(PT_IN(BdptVertex) any) {
  BdptConnection c;
  c.found = false;
  c.L = vec3(0.0f);
  c.visibility = false;
  c.from = vec3(0.0f);
  c.to = vec3(0.0f);
  c.sampled = any;
  c.filmPoint = vec2(0.0f);
  return c;
}

// Samples a light for strategy (1, t) from camera vertex pt (pbrt-v4's SampleLi after the
// light sampler's choice): the emitter from the alias table with uChoose, the point or
// direction on it with uLight (a sphere light's: uniform in the cone it subtends, lights.h).
// found false where it sends nothing towards pt.
PT_INLINE BdptConnection bdptSampleLightFrom(PT_SCENE_PARAM PT_IN(BdptVertex) pt, vec2 uChoose,
                                             vec2 uLight) {
  BdptConnection c = noBdptConnection(pt);
  uint slot = aliasTableSlot(uChoose.x, PT_PARAMS.emitterCount);
  uint index = aliasTablePick(slot, loadEmitter(PT_SCENE_ARG slot), uChoose.y);
  Emitter e = loadEmitter(PT_SCENE_ARG index);
  vec3 Li;
  float pdf;  // solid-angle density of the direction at pt, the light once chosen
  vec3 wi;
  if ((e.triangle & kEmitterLight) != 0u) {
    Light light = loadLight(PT_SCENE_ARG e.triangle & ~kEmitterLight);
    AnalyticLightSample a;
    if (PT_HAS_ENVIRONMENT_IMAGE && light.type == kLightInfinite &&
        PT_PARAMS.environmentWidth != 0u) {
      a = sampleEnvironmentLight(environmentMap(PT_SCENE_ONLY), pt.p, uLight,
                                 PT_PARAMS.sceneRadius);
    } else {
      a = sampleAnalyticLight(light, pt.p, uLight, PT_PARAMS.sceneRadius);
    }
    if (PT_HAS_SPHERE_LIGHTS && light.type == kLightSphere) {
      // The cone's sample is a point of the sphere: an area light's vertex there, with its
      // outward normal (the shadow ray's end, a.target, lies just outside along it), so that
      // the MIS densities are an area light's (pbrt-v4 weighs its sphere's cone sample so).
      vec3 n = normalize(a.target - light.position);
      c.sampled = bdptSphereLightVertex(PT_SCENE_ARG index, light, n, vec3(0.0f), pt.key);
    } else {
      c.sampled = bdptEmptyVertex(kBdptLight, a.target, vec3(0.0f), pt.key);
      c.sampled.lightType = light.type;
      c.sampled.emitter = index;
      c.sampled.w = -a.wi;
    }
    wi = a.wi;
    Li = a.Li;
    pdf = a.pdf;
    c.to = a.target;
  } else {
    // A uniform point of the triangle: its solid-angle density dist^2 / (cos area).
    Triangle tri = loadTriangle(PT_SCENE_ARG e.triangle);
    vec2 b = sampleTriangleBarycentrics(uLight);
    vec3 point = (1.0f - b.x - b.y) * tri.v0 + b.x * tri.v1 + b.y * tri.v2;
    c.sampled = bdptTriangleLightVertex(PT_SCENE_ARG index, point, b, vec3(0.0f), pt.key);
    vec3 toLight = point - pt.p;
    float dist2 = dot(toLight, toLight);
    wi = toLight / sqrt(dist2);
    float cosLight = abs(dot(c.sampled.ng, wi));
    Li = bdptLe(PT_SCENE_ARG c.sampled, pt);
    pdf = dist2 / (cosLight * c.sampled.s.area);
    c.to = bdptSegmentEnd(c.sampled, -wi);
  }
  if (!(pdf > 0.0f) || !(maxComponent(Li) > 0.0f)) return c;
  c.sampled.beta = Li / (pdf * e.pmf);
  c.sampled.pdfFwd = bdptPdfLightOrigin(PT_SCENE_ARG c.sampled, pt);
  c.L = pt.beta * bdptF(PT_SCENE_ARG pt, c.sampled, true) * c.sampled.beta;
  if (bdptOnSurface(pt)) c.L *= abs(dot(wi, pt.ns));
  c.from = bdptSegmentEnd(pt, wi);
  c.visibility = true;
  c.found = maxComponent(c.L) > 0.0f;
  return c;
}

// Strategy (s, t) for the subpaths lightPath and cameraPath (s <= lightPath.count, 1 <= t <=
// cameraPath.count, not s = t = 1): the contribution before its weight and shadow ray.
// uChoose, uLight: the numbers of the light sample (s = 1) or the lens point (t = 1, .. uLight).
PT_INLINE BdptConnection bdptConnect(PT_SCENE_PARAM PT_BDPT_PATHS_PARAM uint s, uint t,
                                     vec2 uChoose, vec2 uLight) {
  BdptVertex pt = cameraPath.v[t - 1u];
  BdptConnection c = noBdptConnection(pt);
  // A camera subpath that left the scene ends at the infinite light: only s = 0 takes it.
  if (t > 1u && s != 0u && pt.type == kBdptLight) return c;
  if (s == 0u) {
    // The camera subpath as a whole path: the light its last vertex emits.
    if (!bdptIsLight(pt)) return c;
    c.L = bdptLe(PT_SCENE_ARG pt, cameraPath.v[max(t, 2u) - 2u]) * pt.beta;
  } else if (t == 1u) {
    // A point on the lens seen from the light subpath's last vertex (light tracing).
    BdptVertex qs = lightPath.v[max(s, 1u) - 1u];
    if (!bdptIsConnectible(qs)) return c;
    CameraWiSample cs = sampleCameraWi(PT_PARAMS.camera, qs.p, uLight);
    if (!cs.found) return c;
    c.sampled = bdptCameraVertex(PT_PARAMS.camera, cs.lensOffset, vec3(cs.We / cs.pdf), qs.key);
    c.filmPoint = cs.filmPoint;
    c.L = qs.beta * bdptF(PT_SCENE_ARG qs, c.sampled, false) * c.sampled.beta;
    if (bdptOnSurface(qs)) c.L *= abs(dot(cs.wi, qs.ns));
    c.from = bdptSegmentEnd(qs, cs.wi);
    c.to = cs.pLens;
    c.visibility = true;
  } else if (s == 1u) {
    // A point on a light seen from the camera subpath's last vertex.
    if (!bdptIsConnectible(pt)) return c;
    return bdptSampleLightFrom(PT_SCENE_ARG pt, uChoose, uLight);
  } else {
    // A segment between the two subpaths' last vertices.
    BdptVertex qs = lightPath.v[max(s, 1u) - 1u];
    if (!bdptIsConnectible(qs) || !bdptIsConnectible(pt)) return c;
    vec3 d = qs.p - pt.p;
    float dist2 = dot(d, d);
    if (!(dist2 > 0.0f)) return c;
    d /= sqrt(dist2);
    c.L = qs.beta * bdptF(PT_SCENE_ARG qs, pt, false) * bdptF(PT_SCENE_ARG pt, qs, true) * pt.beta;
    c.L *= bdptGeometry(qs, pt, d, dist2);
    c.from = bdptSegmentEnd(pt, d);
    c.to = bdptSegmentEnd(qs, -d);
    c.visibility = true;
  }
  c.found = maxComponent(c.L) > 0.0f;
  return c;
}

// ---- The MIS weight ------------------------------------------------------------------------

// One factor of the recursion: the squared ratio of a vertex's two densities, a zero density
// (a delta's) counting as 1.
PT_INLINE float bdptMisRatio(float pdfRev, float pdfFwd) {
  float r = (pdfRev != 0.0f ? pdfRev : 1.0f) / (pdfFwd != 0.0f ? pdfFwd : 1.0f);
  return r * r;
}

// The densities of the four vertices about the connection of strategy (s, t), with which the
// other side would have sampled them (pbrt-v4's temporary assignments in MISWeight): pt's and
// its predecessor's from the light side, qs's and its predecessor's from the camera side. Each
// is used by bdptMisWeight in place of the vertex's stored pdfRev.
struct BdptConnectionDensities {
  float ptRev;
  float ptMinusRev;
  float qsRev;
  float qsMinusRev;
};

// pt, qs: the connection's vertices (the sampled one where s or t is 1).
PT_INLINE BdptConnectionDensities bdptConnectionDensities(
    PT_SCENE_PARAM PT_BDPT_PATHS_PARAM PT_IN(BdptVertex) pt, PT_IN(BdptVertex) qs, uint s, uint t) {
  BdptConnectionDensities r = BdptConnectionDensities(0.0f, 0.0f, 0.0f, 0.0f);
  // The predecessors (unused where they do not exist: any vertex stands in).
  BdptVertex ptMinus = t > 1u ? cameraPath.v[max(t, 2u) - 2u] : pt;
  BdptVertex qsMinus = s > 1u ? lightPath.v[max(s, 2u) - 2u] : qs;
  if (s > 0u) {
    r.ptRev = bdptPdf(PT_SCENE_ARG qsMinus, qs, pt);
    if (t > 1u) r.ptMinusRev = bdptPdf(PT_SCENE_ARG qs, pt, ptMinus);
    r.qsRev = bdptPdf(PT_SCENE_ARG ptMinus, pt, qs);
    if (s > 1u) r.qsMinusRev = bdptPdf(PT_SCENE_ARG pt, qs, qsMinus);
  } else {
    // The camera subpath ends on a light: the densities of a light subpath starting there.
    r.ptRev = bdptPdfLightOrigin(PT_SCENE_ARG pt, ptMinus);
    if (t > 1u) r.ptMinusRev = bdptPdfLight(PT_SCENE_ARG pt, ptMinus);
  }
  return r;
}

// The power heuristic's weight of strategy (s, t) against every other strategy that could
// have sampled the same path (pbrt-v4's MISWeight): 1 / (1 + sum of the other strategies'
// density ratios, squared). `sampled`: the vertex strategy s = 1 or t = 1 sampled.
PT_INLINE float bdptMisWeight(PT_SCENE_PARAM PT_BDPT_PATHS_PARAM PT_IN(BdptVertex) sampled, uint s,
                              uint t) {
  if (s + t == 2u) return 1.0f;
  BdptVertex pt = t == 1u ? sampled : cameraPath.v[t - 1u];
  BdptVertex qs = s == 1u ? sampled : (s > 0u ? lightPath.v[max(s, 1u) - 1u] : pt);
  BdptConnectionDensities d = bdptConnectionDensities(PT_SCENE_ARG PT_BDPT_PATHS_ARG pt, qs, s, t);
  float sumRi = 0.0f;
  // The strategies that take fewer camera vertices (the connection vertices are never delta:
  // a strategy connects only at vertices that are not).
  float ri = 1.0f;
  for (uint i = t - 1u; i > 0u; --i) {
    float pdfRev = i == t - 1u ? d.ptRev : (i == t - 2u ? d.ptMinusRev : cameraPath.v[i].pdfRev);
    float pdfFwd = i == t - 1u ? pt.pdfFwd : cameraPath.v[i].pdfFwd;
    bool delta = i == t - 1u ? false : cameraPath.v[i].delta;
    ri *= bdptMisRatio(pdfRev, pdfFwd);
    if (!delta && !cameraPath.v[i - 1u].delta) sumRi += ri;
  }
  // Those that take fewer light vertices.
  ri = 1.0f;
  for (uint j = s; j > 0u; --j) {
    uint i = j - 1u;
    float pdfRev = i == s - 1u ? d.qsRev : (i == s - 2u ? d.qsMinusRev : lightPath.v[i].pdfRev);
    float pdfFwd = i == s - 1u ? qs.pdfFwd : lightPath.v[i].pdfFwd;
    bool delta = i == s - 1u ? false : lightPath.v[i].delta;
    bool deltaBefore = i > 0u ? lightPath.v[max(i, 1u) - 1u].delta
                              : bdptIsDeltaLight(i == s - 1u ? qs : lightPath.v[0]);
    ri *= bdptMisRatio(pdfRev, pdfFwd);
    if (!delta && !deltaBefore) sumRi += ri;
  }
  return 1.0f / (1.0f + sumRi);
}

#ifdef __cplusplus
}  // namespace pt
#endif

#endif  // PT_BDPT_CONNECT_H

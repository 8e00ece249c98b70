// The volume integrator's outline in the shader (pathtrace.comp's variant PT_VOLPATH, for
// scenes with media): one iteration of host/cpu/volpath.cpp's loop, over the same steps of
// volume_vertex.h and path_vertex.h. What is the shader's own: the traversal (bvh.glsl), a
// ray the fast test gave up on traced again with the exact test at once (the path variant
// defers it: see Retrace), and the loops counted for lavapipe's cap.

// The closest hit along origin + t direction, t in (0, tMax).
bool traceClosest(vec3 origin, vec3 direction, float tMax, out HitData hit) {
  gRays++;
  bool inexact;
  bool found =
      traceRayWith(/*exact=*/false, origin, direction, tMax, /*anyHit=*/false, hit, inexact);
  if (inexact) {
    found = traceRayWith(/*exact=*/true, origin, direction, tMax, /*anyHit=*/false, hit, inexact);
  }
  return found;
}

// Traces the shadow ray of light sample ls, which starts in `medium`, through the interfaces
// and media on its way: false when a surface blocks it; tr gathers the media's transmittance.
bool traceShadowThroughMedia(LightSample ls, uint medium, uint hero, inout ShadowTransmittance tr) {
  vec3 from = ls.from;
  for (uint crossing = 0u; crossing <= kMaxInterfaceCrossings; ++crossing) {
    gLoopIterations++;
    vec3 direction = ls.to - from;
    HitData hit;
    bool found = traceClosest(from, direction, 1.0, hit);
    Triangle tri;
    if (found) {
      tri = loadTriangle(hit.triangle);
      if (loadMaterial(tri.material).type != kMaterialInterface) return false;
    }
    if (medium != kNoMedium) {
      float len = length(direction);
      float tEnd = (found ? hit.t : 1.0) * len;
      if (!trackShadowSegment(tr, medium, hero, from, direction / len, tEnd)) return false;
    }
    if (!found) return true;
    medium = crossInterface(hit.triangle, tri, hitBarycentrics(from, direction, tri), direction,
                            medium, from);
  }
  return false;
}

// One iteration of sampleRadianceVolume's loop: traces the path's ray, flies through the
// medium it is in (which may scatter the path there), or finds a surface: crosses it if it
// only bounds media, else adds its emission, samples a light, scatters. Returns true when the
// path has ended.
bool extendPath(inout Path path, uvec2 pixel, inout Retrace retrace) {
  uint seed = params.seed;
  bool sobol = PT_SOBOL;
  uint sampleIndex = path.sampleIndex;
  // Find the closest surface along the ray.
#ifndef PT_NO_BSDF_MATERIALS
  if (kAlphaCutouts) gAlphaU = pathAlphaRandom(pixel, sampleIndex, path.vol.depth, seed);
#endif
  HitData hit;
  bool found = traceClosest(path.origin, path.direction, 1.0 / 0.0, hit);

  // In a medium: fly through it to that surface.
  if (path.vol.medium != kNoMedium) {
    float len = length(path.direction);
    vec3 d = path.direction / len;
    vec3 p;
    float g;
    uint flight = trackFlight(path.vol, path.origin, d, found ? hit.t * len : 1.0 / 0.0, p, g);
    if (flight == kFlightEnded) return true;
    if (flight == kFlightScattered) {
      if (path.vol.depth == params.maxDepth) return true;
      VertexKey key =
          VertexKey(pixel, sampleIndex, kDimFirstBounce + kDimsPerBounce * path.vol.depth);
      ++path.vol.depth;
      if (neeOn()) {
        vec2 uLight = random2(sobol, pixel, sampleIndex, key.dim + kDimLightPoint, seed);
        LightSample ls = sampleLightAt(
            mediumPoint(p, -d, g), key,
            random2(sobol, pixel, sampleIndex, key.dim + kDimLightChoose, seed), uLight);
        if (ls.found) {
#ifndef PT_NO_BSDF_MATERIALS
          if (kAlphaCutouts) gAlphaU = shadowAlphaRandom(uLight);
#endif
          ShadowTransmittance tr = startShadowTransmittance(key);
          if (traceShadowThroughMedia(ls, path.vol.medium, path.vol.hero, tr)) {
            path.vol.path.L += volumeLightContribution(path.vol, ls.f, ls.f.x, ls, tr);
          }
        }
      }
      vec3 wi;
      if (!scatterInMedium(path.vol, -d, g,
                           random2(sobol, pixel, sampleIndex, key.dim + kDimBsdf, seed), wi)) {
        return true;
      }
      startFlight(path.vol, key, p);
      path.crossings = 0u;
      path.origin = p;
      path.direction = wi;
      return false;
    }
  }

  if (!found) {
    // The ray leaves the scene: the infinite light's radiance, weighed as an emitter's.
    addVolumeEnvironmentFound(path.vol, path.direction);
    return true;
  }
  Triangle tri = loadTriangle(hit.triangle);
  vec3 b = hitBarycentrics(path.origin, path.direction, tri);
  // A surface that only bounds media: the ray goes on beyond it, in the medium there.
  if (loadMaterial(tri.material).type == kMaterialInterface) {
    if (++path.crossings > kMaxInterfaceCrossings) return true;
    path.vol.medium =
        crossInterface(hit.triangle, tri, b, path.direction, path.vol.medium, path.origin);
    return false;
  }
  SurfacePoint s = surfacePointAt(hit.triangle, tri, b, -path.direction, path.vol.path.rd);

  // Emitted light found by this ray, weighed against light sampling.
  addVolumeEmissionFound(path.vol, tri, s);

  // Stop after maxDepth scattering events.
  if (path.vol.depth == params.maxDepth) return true;
  VertexKey key = VertexKey(pixel, sampleIndex, kDimFirstBounce + kDimsPerBounce * path.vol.depth);
  ++path.vol.depth;

  // Light sampling: the shadow ray leaves into the medium on the light's side.
  if (samplesLightAt(s)) {
    vec2 uLight = random2(sobol, pixel, sampleIndex, key.dim + kDimLightPoint, seed);
    LightSample ls = sampleLightAt(
        s, key, random2(sobol, pixel, sampleIndex, key.dim + kDimLightChoose, seed), uLight);
    if (ls.found) {
#ifndef PT_NO_BSDF_MATERIALS
      if (kAlphaCutouts) gAlphaU = shadowAlphaRandom(uLight);
#endif
      ShadowTransmittance tr = startShadowTransmittance(key);
      uint medium = mediumAfter(tri.primitive, s.ng, ls.to - ls.from, path.vol.medium);
      if (traceShadowThroughMedia(ls, medium, path.vol.hero, tr)) {
        path.vol.path.L += volumeLightContribution(path.vol, ls.f * ls.scale,
                                                   lightSampleBsdfPdf(s, key, ls), ls, tr);
      }
    }
  }

  // The BSDF's sample for the next direction, and the medium it leads into.
  vec2 uRoulette = random2(sobol, pixel, sampleIndex, key.dim + kDimRoulette, seed);
  vec3 wi;
  if (!sampleBsdfAt(s, key, path.vol.path, uRoulette.y,
                    random2(sobol, pixel, sampleIndex, key.dim + kDimBsdf, seed), wi)) {
    return true;
  }
  afterSurfaceScatter(path.vol);
  if (maxComponent(path.vol.path.beta) <= 0.0) return true;
  if (!survivesVolumeRoulette(path.vol, uRoulette.x)) return true;
  path.vol.medium = mediumAfter(tri.primitive, s.ng, wi, path.vol.medium);
  startFlight(path.vol, key, s.p);
  path.crossings = 0u;
  path.origin = nextRayOrigin(s, wi);
  path.direction = wi;
  return false;
}

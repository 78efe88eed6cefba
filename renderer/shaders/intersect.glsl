// Ray queries against the BVH (layout.h), shared by GLSL and C++.
//
// Two queries serve the four ray types of method.md section 3: closest_hit
// for radiance rays (mixed: every primitive; real: the real proxy only) and
// shadow_query for shadow rays, which answers for the mixed and the real
// shadow ray in one traversal.

struct Ray {
  vec3 origin;
  vec3 dir; // unit length
};

struct Hit {
  float t;    // CAMHEAD_NO_HIT when nothing was hit
  uint prim;  // index into primitives
};

#define CAMHEAD_NO_HIT 3.0e38f
#define CAMHEAD_STACK_SIZE 64

#define OCCLUDED_BY_VIRTUAL 1u
#define OCCLUDED_BY_REAL 2u

// The primitive's flags are in p0.w; callers fetch a primitive once and ask
// it everything (on lavapipe a fetch is a gather of three texels).
uint prim_bits(Primitive prim) {
  return floatBitsToUint(prim.p0.w);
}

bool prim_is_real(Primitive prim) {
  return (prim_bits(prim) & PRIM_REAL_BIT) != 0u;
}

uint prim_material(Primitive prim) {
  return prim_bits(prim) & PRIM_MATERIAL_MASK;
}

// Reciprocal direction without infinities, so that the slab test never
// computes 0 * inf for rays parallel to a slab.
vec3 safe_reciprocal(vec3 d) {
  float x = abs(d.x) < 1e-20f ? 1e-20f : d.x;
  float y = abs(d.y) < 1e-20f ? 1e-20f : d.y;
  float z = abs(d.z) < 1e-20f ? 1e-20f : d.z;
  return vec3(1.0f / x, 1.0f / y, 1.0f / z);
}

// Entry distance of the ray into the box, or CAMHEAD_NO_HIT.
float box_entry(vec3 origin, vec3 inv_dir, vec4 bmin, vec4 bmax, float t_max) {
  vec3 t0 = (vec3(bmin) - origin) * inv_dir;
  vec3 t1 = (vec3(bmax) - origin) * inv_dir;
  vec3 lo = min(t0, t1);
  vec3 hi = max(t0, t1);
  float t_enter = max(max(lo.x, lo.y), max(lo.z, 0.0f));
  float t_exit = min(min(hi.x, hi.y), min(hi.z, t_max));
  return t_enter <= t_exit ? t_enter : CAMHEAD_NO_HIT;
}

// Moeller-Trumbore; p0 = v0, p1 = v1 - v0, p2 = v2 - v0. Two-sided.
float intersect_triangle(Ray ray, Primitive prim, float t_min, float t_max) {
  vec3 e1 = vec3(prim.p1);
  vec3 e2 = vec3(prim.p2);
  vec3 pvec = cross(ray.dir, e2);
  float det = dot(e1, pvec);
  if (abs(det) < 1e-20f) {
    return CAMHEAD_NO_HIT;
  }
  float inv_det = 1.0f / det;
  vec3 tvec = ray.origin - vec3(prim.p0);
  float u = dot(tvec, pvec) * inv_det;
  if (u < 0.0f || u > 1.0f) {
    return CAMHEAD_NO_HIT;
  }
  vec3 qvec = cross(tvec, e1);
  float v = dot(ray.dir, qvec) * inv_det;
  if (v < 0.0f || u + v > 1.0f) {
    return CAMHEAD_NO_HIT;
  }
  float t = dot(e2, qvec) * inv_det;
  return (t > t_min && t < t_max) ? t : CAMHEAD_NO_HIT;
}

// Nearest root beyond t_min, so that a ray starting inside (glass) exits.
float intersect_sphere(Ray ray, Primitive prim, float t_min, float t_max) {
  vec3 oc = ray.origin - vec3(prim.p0);
  float radius = prim.p1.x;
  float b = dot(oc, ray.dir);
  // c computed as (|oc| - r)(|oc| + r) keeps precision for distant spheres.
  float len_oc = length(oc);
  float c = (len_oc - radius) * (len_oc + radius);
  // Discriminant from the closest-approach vector (Haines et al., Ray
  // Tracing Gems ch. 7): robust when the sphere is small and far away.
  vec3 closest = oc - b * ray.dir;
  float disc = radius * radius - dot(closest, closest);
  if (disc < 0.0f) {
    return CAMHEAD_NO_HIT;
  }
  float root = sqrt(disc);
  float q = -b - (b >= 0.0f ? root : -root);
  float t_a = q;
  float t_b = (q != 0.0f) ? c / q : -b;
  float t_near = min(t_a, t_b);
  float t_far = max(t_a, t_b);
  if (t_near > t_min && t_near < t_max) {
    return t_near;
  }
  if (t_far > t_min && t_far < t_max) {
    return t_far;
  }
  return CAMHEAD_NO_HIT;
}

// Whether a primitive is a sphere; constant where the pipeline has one kind.
bool prim_is_sphere(Primitive prim) {
  return KERNEL_HAS(KERNEL_SPHERES) &&
         (!KERNEL_HAS(KERNEL_TRIANGLES) || (prim_bits(prim) >> 24) == PRIM_SPHERE);
}

float intersect_primitive(Ray ray, Primitive prim, float t_min, float t_max) {
  return prim_is_sphere(prim) ? intersect_sphere(ray, prim, t_min, t_max)
                              : intersect_triangle(ray, prim, t_min, t_max);
}

// Closest hit in (t_min, t_max). real_only: the real radiance ray, which sees
// the real proxy alone.
Hit closest_hit(Ray ray, float t_min, float t_max, bool real_only) {
  Hit hit;
  hit.t = CAMHEAD_NO_HIT;
  hit.prim = 0u;
  float t_best = t_max;
  vec3 inv_dir = safe_reciprocal(ray.dir);
  uint stack[CAMHEAD_STACK_SIZE];
  int top = 0;
  BvhNode node = node_at(0u);
  if (box_entry(ray.origin, inv_dir, node.bmin, node.bmax, t_best) == CAMHEAD_NO_HIT) {
    return hit;
  }
  // Each round takes the ray down through interior nodes, nearer child
  // first, to a leaf (or a dead end), tests the leaf and pops the next
  // subtree. In separate loops a SIMD executor runs an interior step
  // without a masked leaf test and pop beside it (bench/RESULTS.md).
  for (;;) {
    bool dead_end = false;
    if (floatBitsToUint(node.bmax.w) == 0u) {
      do {
        uint left = floatBitsToUint(node.bmin.w);
        uint right = left + 1u;
        BvhNode left_node = node_at(left);
        BvhNode right_node = node_at(right);
        float t_left = box_entry(ray.origin, inv_dir, left_node.bmin, left_node.bmax, t_best);
        float t_right = box_entry(ray.origin, inv_dir, right_node.bmin, right_node.bmax, t_best);
        if (t_left != CAMHEAD_NO_HIT && t_right != CAMHEAD_NO_HIT) {
          bool left_first = t_left <= t_right;
          if (top < CAMHEAD_STACK_SIZE) {
            stack[top] = left_first ? right : left;
            ++top;
          }
          node = left_first ? left_node : right_node;
        } else if (t_left != CAMHEAD_NO_HIT) {
          node = left_node;
        } else if (t_right != CAMHEAD_NO_HIT) {
          node = right_node;
        } else {
          dead_end = true;
        }
      } while (!dead_end && floatBitsToUint(node.bmax.w) == 0u);
    }
    if (!dead_end) {
      uint first = floatBitsToUint(node.bmin.w);
      uint count = floatBitsToUint(node.bmax.w);
      uint i = first;
      do {
        Primitive prim = primitive_at(i);
        if (!real_only || prim_is_real(prim)) {
          float t = intersect_primitive(ray, prim, t_min, t_best);
          if (t < t_best) {
            t_best = t;
            hit.t = t;
            hit.prim = i;
          }
        }
      } while (++i < first + count);
    }
    // Pop, skipping subtrees that now start beyond the best hit.
    bool found = false;
    if (top > 0) {
      do {
        --top;
        node = node_at(stack[top]);
        found = box_entry(ray.origin, inv_dir, node.bmin, node.bmax, t_best) != CAMHEAD_NO_HIT;
      } while (top > 0 && !found);
    }
    if (!found) {
      break;
    }
  }
  return hit;
}

// Which kinds of geometry block the segment (t_min, t_max): OCCLUDED_BY_REAL
// and/or OCCLUDED_BY_VIRTUAL. One traversal answers the mixed shadow ray
// (blocked by anything) and the real shadow ray (blocked by the real proxy).
// It stops at the first real blocker, or at the first blocker of any kind
// when stop_at_any (the real answer is not needed).
uint shadow_query(Ray ray, float t_min, float t_max, bool real_only, bool stop_at_any) {
  uint occluded = 0u;
  vec3 inv_dir = safe_reciprocal(ray.dir);
  uint stack[CAMHEAD_STACK_SIZE];
  int top = 0;
  BvhNode node = node_at(0u);
  if (box_entry(ray.origin, inv_dir, node.bmin, node.bmax, t_max) == CAMHEAD_NO_HIT) {
    return occluded;
  }
  // In rounds as closest_hit: down to a leaf, its primitives, a pop.
  for (;;) {
    bool dead_end = false;
    if (floatBitsToUint(node.bmax.w) == 0u) {
      do {
        uint left = floatBitsToUint(node.bmin.w);
        uint right = left + 1u;
        BvhNode left_node = node_at(left);
        BvhNode right_node = node_at(right);
        bool enters_left =
            box_entry(ray.origin, inv_dir, left_node.bmin, left_node.bmax, t_max) != CAMHEAD_NO_HIT;
        bool enters_right = box_entry(ray.origin, inv_dir, right_node.bmin, right_node.bmax,
                                      t_max) != CAMHEAD_NO_HIT;
        if (enters_left && enters_right && top < CAMHEAD_STACK_SIZE) {
          stack[top] = right;
          ++top;
        }
        if (enters_left) {
          node = left_node;
        } else if (enters_right) {
          node = right_node;
        } else {
          dead_end = true;
        }
      } while (!dead_end && floatBitsToUint(node.bmax.w) == 0u);
    }
    if (!dead_end) {
      uint first = floatBitsToUint(node.bmin.w);
      uint count = floatBitsToUint(node.bmax.w);
      uint i = first;
      do {
        Primitive prim = primitive_at(i);
        bool real = prim_is_real(prim);
        if (real_only && !real) {
          continue;
        }
        if ((occluded & OCCLUDED_BY_VIRTUAL) != 0u && !real) {
          continue; // already known; only a real blocker can add information
        }
        if (intersect_primitive(ray, prim, t_min, t_max) != CAMHEAD_NO_HIT) {
          occluded |= real ? OCCLUDED_BY_REAL : OCCLUDED_BY_VIRTUAL;
          if (real || stop_at_any) {
            return occluded;
          }
        }
      } while (++i < first + count);
    }
    if (top == 0) {
      break;
    }
    --top;
    node = node_at(stack[top]);
  }
  return occluded;
}

// Radiance that area lights in front of t_max send along the ray. Cycles
// shows area lights to mirror and glass rays (not to camera rays), from their
// front side, and lets the ray continue behind them.
vec3 area_lights_along(Ray ray, float t_max) {
  vec3 sum = vec3(0.0f);
  if (!KERNEL_HAS(KERNEL_AREA_LIGHTS) || frame.image.w == 0u) {
    return sum;
  }
  uint li = 0u;
  do {
    Light light = light_at(li);
    if (floatBitsToUint(light.position.w) != LIGHT_AREA) {
      continue;
    }
    vec3 n = vec3(light.normal);
    float facing = dot(ray.dir, n);
    if (facing >= 0.0f) {
      continue; // seen from behind: one-sided
    }
    float t = dot(vec3(light.position) - ray.origin, n) / facing;
    if (t <= 0.0f || t >= t_max) {
      continue;
    }
    vec3 q = ray.origin + t * ray.dir - vec3(light.position);
    vec3 u = vec3(light.axis_u);
    vec3 v = vec3(light.axis_v);
    float a = dot(q, u) / dot(u, u);
    float b = dot(q, v) / dot(v, v);
    if (abs(a) <= 0.5f && abs(b) <= 0.5f) {
      sum += vec3(light.emission);
    }
  } while (++li < frame.image.w);
  return sum;
}

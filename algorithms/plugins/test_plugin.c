/* Plugins for the loader's tests, written in plain C99 against plugin.h alone: one source, compiled once
 * per variant (TEST_PLUGIN_VARIANT, see CMakeLists.txt).
 *
 *  0 "line": a working plugin. From every seed, a straight stalk that climbs one `step` per growth step
 *    along the seed's direction until `length` nodes or a solid (host->inside) stops it; a leaf at each
 *    tip. Its `fault` parameter makes it crash, hang, exhaust memory or report errors, for the tests of
 *    how a suite records a misbehaving plugin (an exit() it never reports, a message of a megabyte, a flood of stderr,
 * a full disk), give NaN to the queries (nan_query), hand over an invalid plant (bad_parent, nan_node) or
 * one that differs from process to process (by_process), or (line_v3) a decal on a mesh the scene lacks (bad_decal).
 * 1 no entry point; 2 another ABI version; 3 a built-in's name; 4 a malformed parameter table;
 * 5 an entry() that crashes; 6 an entry() that calls exit(0); 7 an entry() that closes every descriptor and
 * waits forever. All of these declare ABI version 1 and check that they are given version 1's host table.
 * 8 "line_v2": the line in ABI version 2, with blossoms and tinted leaves (organ shapes and tints) and per-node
 * `height` and `Cd` attributes computed with the host's parallel_for; it checks it is given version 2's host table.
 * 9 "line_v3": line_v2 in ABI version 3, adding a node group per stalk, a decal over the first mesh with texture
 * coordinates (planar where none has them), and the surface frame where the line from above that mesh's middle
 * meets the mesh, given as stats for the tests to compare with the mesh's file. */
#define _POSIX_C_SOURCE 200809L /* close() and pause() under C99 without extensions */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "growbench/plugin.h"

#ifndef TEST_PLUGIN_VARIANT
#define TEST_PLUGIN_VARIANT 0
#endif

static const char* const kFaults[] = {"none",      "crash",      "hang",         "oom",        "fail",
                                      "input",     "exit3",      "long_message", "flood",      "disk_full",
                                      "nan_query", "bad_parent", "nan_node",     "by_process", "bad_decal"};
enum { kFaultCount = sizeof kFaults / sizeof kFaults[0] };

static const growbench_param kParams[] = {
    {"length", GROWBENCH_PARAM_INT, {20, 0.0, 0, NULL, {0, 0, 0}}, 1, 100000, "", "nodes per stalk", NULL, 0},
#if TEST_PLUGIN_VARIANT == 4
    {"step", GROWBENCH_PARAM_REAL, {0, 5.0, 0, NULL, {0, 0, 0}}, 0.001, 1.0, "m", "length of one step", NULL, 0},
#else
    {"step", GROWBENCH_PARAM_REAL, {0, 0.02, 0, NULL, {0, 0, 0}}, 0.001, 1.0, "m", "length of one step", NULL, 0},
#endif
    {"fault",
     GROWBENCH_PARAM_CHOICE,
     {0, 0.0, 0, "none", {0, 0, 0}},
     1,
     0,
     "",
     "misbehave, for tests",
     kFaults,
     kFaultCount},
};

static const char* const kTestParams[] = {"length=8"};

typedef struct state {
  const growbench_host* host;
  const growbench_scene* scene;
  int64_t length;
  float step;
  int fault;
  growbench_node* nodes;
  uint64_t node_count;
  growbench_organ* organs;
  uint64_t organ_count;
  int64_t* tip; /* per seed: its stalk's last node, or -1 when it has stopped */
  int64_t steps;
  /* line_v2's styles: per organ a shape and a tint; per node a height and a colour */
  uint16_t* organ_shape;
  growbench_vec3* organ_tint;
  float* height;
  float* color;
  growbench_attribute attributes[2];
  /* line_v3: per node a group; one decal; the probe of the surface frames (stats) */
  int32_t* groups;
  growbench_decal decal;
  uint8_t pixels[4 * 2 * 4];
  growbench_stat stats[10];
  uint32_t stat_count;
} state;

#if TEST_PLUGIN_VARIANT >= 8
/* line_v2 colours each node by its height, one chunk of nodes at a time on the host's threads. */
static void style_nodes(void* user, uint64_t begin, uint64_t end) {
  state* s = (state*)user;
  uint64_t k;
  for (k = begin; k < end; ++k) {
    const float h = s->nodes[k].position.y;
    s->height[k] = h;
    s->color[3 * k] = 0.2f;
    s->color[3 * k + 1] = h > 1.0f ? 1.0f : (h < 0.0f ? 0.0f : h);
    s->color[3 * k + 2] = 0.1f;
  }
}
#endif

#if TEST_PLUGIN_VARIANT == 9
static void add_stat(state* s, const char* name, double value) {
  s->stats[s->stat_count].name = name;
  s->stats[s->stat_count++].value = value;
}

/* The first mesh with texture coordinates, and the surface frame where the line down the +Z axis through the
 * middle of its bounds meets it: stats uv_mesh (-1: none), uv_count, probe_u, probe_v, the unit dp/du and dp/dv
 * and their lengths. A point that is not finite must find no frame. */
static int probe_surface(state* s) {
  const growbench_host* h = s->host;
  const float* uvs = NULL;
  const uint32_t* uv_triangles = NULL;
  uint64_t uv_count = 0, k;
  uint32_t m;
  growbench_vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY}, q;
  growbench_closest_hit hit;
  growbench_surface_point at[2];
  growbench_surface_frame frame[2];
  float du, dv;
  for (m = 0; m < s->scene->mesh_count; ++m)
    if (h->mesh_uvs(h->context, m, &uvs, &uv_count, &uv_triangles)) break;
  add_stat(s, "uv_mesh", m < s->scene->mesh_count ? (double)m : -1.0);
  add_stat(s, "uv_count", (double)uv_count);
  if (m == s->scene->mesh_count) return uvs == NULL && uv_triangles == NULL;
  for (k = 0; k < s->scene->meshes[m].vertex_count; ++k) {
    const growbench_vec3 v = s->scene->meshes[m].vertices[k];
    lo.x = fminf(lo.x, v.x), lo.y = fminf(lo.y, v.y), lo.z = fminf(lo.z, v.z);
    hi.x = fmaxf(hi.x, v.x), hi.y = fmaxf(hi.y, v.y), hi.z = fmaxf(hi.z, v.z);
  }
  q.x = 0.5f * (lo.x + hi.x), q.y = 0.5f * (lo.y + hi.y), q.z = hi.z + 1.0f;
  h->closest_points(h->context, &q, 1, INFINITY, 0, &hit);
  at[0].point = hit.point, at[0].mesh = hit.mesh, at[0].triangle = hit.triangle;
  at[1] = at[0];
  at[1].point.x = NAN;
  h->surface_frames(h->context, at, 2, frame);
  if (!hit.found || hit.mesh != m || !frame[0].found || frame[1].found) return 0;
  du = sqrtf(frame[0].dp_du.x * frame[0].dp_du.x + frame[0].dp_du.y * frame[0].dp_du.y +
             frame[0].dp_du.z * frame[0].dp_du.z);
  dv = sqrtf(frame[0].dp_dv.x * frame[0].dp_dv.x + frame[0].dp_dv.y * frame[0].dp_dv.y +
             frame[0].dp_dv.z * frame[0].dp_dv.z);
  add_stat(s, "probe_u", frame[0].u);
  add_stat(s, "probe_v", frame[0].v);
  add_stat(s, "probe_du_x", frame[0].dp_du.x / du);
  add_stat(s, "probe_du_length", du);
  add_stat(s, "probe_dv_y", frame[0].dp_dv.y / dv);
  add_stat(s, "probe_dv_length", dv);
  add_stat(s, "probe_normal_z", frame[0].normal.z);
  return 1;
}
#endif

static growbench_instance* create(const growbench_host* host) {
  state* s = (state*)calloc(1, sizeof(state));
  if (!s) host->fail(host->context, "out of memory");
  if (s) s->host = host;
  return (growbench_instance*)s;
}

static int32_t start(growbench_instance* instance, const growbench_scene* scene, const growbench_value* params,
                     uint64_t seed) {
  state* s = (state*)instance;
  uint32_t i;
  (void)seed;
  s->scene = scene;
#if TEST_PLUGIN_VARIANT == 0
  /* A version-1 plugin must be given the host table a version-1 host gave. */
  if (s->host->abi_version != 1 || s->host->struct_size != offsetof(growbench_host, parallel_for)) {
    s->host->fail(s->host->context, "a version-1 plugin was given a newer host table");
    return GROWBENCH_ERROR;
  }
#elif TEST_PLUGIN_VARIANT == 8
  if (s->host->abi_version != 2 || s->host->struct_size != offsetof(growbench_host, mesh_uvs)) {
    s->host->fail(s->host->context, "a version-2 plugin was given another host table");
    return GROWBENCH_ERROR;
  }
#elif TEST_PLUGIN_VARIANT == 9
  if (s->host->abi_version != 3 || s->host->struct_size != sizeof(growbench_host)) {
    s->host->fail(s->host->context, "a version-3 plugin was given another host table");
    return GROWBENCH_ERROR;
  }
  add_stat(s, "steps", 0.0);
  if (!probe_surface(s)) {
    s->host->fail(s->host->context, "the surface frames answered wrongly");
    return GROWBENCH_ERROR;
  }
#endif
  s->length = params[0].integer;
  s->step = (float)params[1].real;
  for (s->fault = 0; s->fault < kFaultCount && strcmp(kFaults[s->fault], params[2].text) != 0; ++s->fault) {
  }
  if (s->fault == 5) {
    s->host->fail(s->host->context, "fault=input: this scene will not do");
    return GROWBENCH_INPUT_ERROR;
  }
  if (scene->seed_count == 0) {
    s->host->fail(s->host->context, "the scene has no seeds");
    return GROWBENCH_INPUT_ERROR;
  }
  s->nodes = (growbench_node*)calloc((size_t)(scene->seed_count * s->length), sizeof(growbench_node));
  s->organs = (growbench_organ*)calloc(scene->seed_count, sizeof(growbench_organ));
  s->tip = (int64_t*)calloc(scene->seed_count, sizeof(int64_t));
  if (!s->nodes || !s->organs || !s->tip) {
    s->host->fail(s->host->context, "out of memory");
    return GROWBENCH_ERROR;
  }
  for (i = 0; i < scene->seed_count; ++i) {
    growbench_node* n = &s->nodes[s->node_count];
    n->position = scene->seeds[i].position;
    if (s->fault == 13) n->position.x += 1e-6f * (float)(getpid() % 9973); /* a plant that differs by process */
    n->radius = 0.004f;
    n->parent = -1;
    n->shoot = i;
    s->tip[i] = (int64_t)s->node_count++;
  }
  return GROWBENCH_OK;
}

/* fault=nan_query: rays, occluded and light_visible given NaN and infinite inputs answer "no hit", "not
 * occluded" and "not lit" (docs/plugins.md), and the process goes on. */
static int queries_take_nan(state* s) {
  const float nan = NAN, inf = INFINITY;
  const growbench_vec3 bad[3] = {{nan, 0.5f, 0.0f}, {inf, 0.0f, 0.0f}, {0.0f, -inf, nan}};
  growbench_ray rays[4];
  growbench_ray_hit hits[4];
  uint8_t occluded[4], lit[3], inside[3];
  growbench_closest_hit near[3];
  float distance[3];
  int k;
  for (k = 0; k < 3; ++k) {
    rays[k].origin = bad[k];
    rays[k].direction = bad[(k + 1) % 3];
    rays[k].tmin = 0.0f;
    rays[k].tmax = inf;
  }
  rays[3].origin = s->scene->seeds[0].position; /* a finite origin with a NaN interval */
  rays[3].direction = s->scene->seeds[0].direction;
  rays[3].tmin = nan;
  rays[3].tmax = nan;
  memset(hits, 0xff, sizeof hits);
  memset(occluded, 7, sizeof occluded);
  memset(lit, 7, sizeof lit);
  s->host->rays(s->host->context, rays, 4, hits);
  s->host->occluded(s->host->context, rays, 4, occluded);
  s->host->light_visible(s->host->context, bad, 3, 1e-4f, lit);
  for (k = 0; k < 4; ++k)
    if (hits[k].hit != 0 || occluded[k] != 0 || (k < 3 && lit[k] != 0)) {
      s->host->fail(s->host->context, "fault=nan_query: a query on NaN or infinite input answered something");
      return 0;
    }
  /* Points: inside nothing, near no surface, at a distance that is NaN. */
  memset(inside, 7, sizeof inside);
  memset(near, 0xff, sizeof near);
  s->host->inside(s->host->context, bad, 3, inside);
  s->host->closest_points(s->host->context, bad, 3, INFINITY, 0, near);
  for (k = 0; k < 3; ++k) distance[k] = 0.0f;
  if (s->scene->has_sdf && s->host->signed_distance(s->host->context, bad, 3, distance, NULL) == GROWBENCH_OK)
    for (k = 0; k < 3; ++k)
      if (!isnan(distance[k])) inside[k] = 9;
  for (k = 0; k < 3; ++k)
    if (inside[k] != 0 || near[k].found != 0) {
      s->host->fail(s->host->context, "fault=nan_query: a point query on NaN or infinite input answered something");
      return 0;
    }
  return 1;
}

static int32_t step(growbench_instance* instance) {
  state* s = (state*)instance;
  uint32_t i;
  int grew = 0;
  if (s->fault == 1) {
    signal(SIGSEGV, SIG_DFL); /* a plain crash, past any handler a sanitizer installed */
    raise(SIGSEGV);
  }
  if (s->fault == 2)
    while (!s->host->cancelled(s->host->context)) {
    }
  if (s->fault == 3) /* never freed: the trial's process ends next */
    while (malloc(1 << 20)) {
    }
  if (s->fault == 3) {
    s->host->fail(s->host->context, "fault=oom: an allocation was refused");
    return -GROWBENCH_OUT_OF_MEMORY;
  }
  if (s->fault == 4) {
    s->host->fail(s->host->context, "fault=fail: gave up");
    return -GROWBENCH_ERROR;
  }
  if (s->fault == 8 && s->steps == 0) { /* 80 MiB of stderr, then a plant as usual */
    static char line[1 << 16];
    int k;
    memset(line, 'y', sizeof line);
    for (k = 0; k < 1280; ++k) fwrite(line, 1, sizeof line, stderr);
  }
  if (s->fault == 6) exit(3);
  if (s->fault == 9 && !getenv("TEST_PLUGIN_DISK_HAS_ROOM")) { /* as a write to a full disk fails */
    s->host->fail(s->host->context, "cannot write: No space left on device");
    return -GROWBENCH_ERROR;
  } /* the trial's code for out of memory, which it never reported */
  if (s->fault == 7) {
    char* text = (char*)malloc(1u << 20);
    if (text) {
      memset(text, 'x', (1u << 20) - 1);
      text[(1u << 20) - 1] = '\0';
      s->host->fail(s->host->context, text);
      free(text);
    }
    return -GROWBENCH_ERROR;
  }
  if (s->fault == 10 && !queries_take_nan(s)) return -GROWBENCH_ERROR;
  ++s->steps;
  for (i = 0; i < s->scene->seed_count; ++i) {
    const growbench_vec3 d = s->scene->seeds[i].direction;
    const float len = sqrtf(d.x * d.x + d.y * d.y + d.z * d.z);
    growbench_vec3 p;
    uint8_t inside = 0;
    growbench_node* n;
    if (s->tip[i] < 0 || s->steps >= s->length || len <= 0.0f) continue;
    p = s->nodes[s->tip[i]].position;
    p.x += s->step * d.x / len;
    p.y += s->step * d.y / len;
    p.z += s->step * d.z / len;
    s->host->inside(s->host->context, &p, 1, &inside);
    if (inside) {
      s->tip[i] = -1;
      continue;
    }
    n = &s->nodes[s->node_count];
    n->position = p;
    n->radius = 0.004f;
    n->parent = (int32_t)s->tip[i];
    n->shoot = i;
    n->birth_step = (uint32_t)s->steps;
    s->tip[i] = (int64_t)s->node_count++;
    grew = 1;
  }
  return grew;
}

static int32_t finish(growbench_instance* instance) {
  state* s = (state*)instance;
  uint64_t k;
  for (k = 0; k < s->node_count; ++k) {
    int is_tip = 1;
    uint64_t m;
    for (m = k + 1; m < s->node_count && is_tip; ++m) is_tip = s->nodes[m].parent != (int32_t)k;
    if (is_tip && s->nodes[k].parent >= 0) {
      growbench_organ* o = &s->organs[s->organ_count++];
      o->position = s->nodes[k].position;
      o->orientation[0] = 1.0f;
      o->size = 0.03f;
      o->kind = GROWBENCH_ORGAN_LEAF;
      o->node = (int32_t)k;
    }
  }
#if TEST_PLUGIN_VARIANT >= 8
  s->organ_shape = (uint16_t*)calloc(s->organ_count + 1, sizeof(uint16_t));
  s->organ_tint = (growbench_vec3*)calloc(s->organ_count + 1, sizeof(growbench_vec3));
  s->height = (float*)calloc(s->node_count + 1, sizeof(float));
  s->color = (float*)calloc(3 * s->node_count + 1, sizeof(float));
  if (!s->organ_shape || !s->organ_tint || !s->height || !s->color) {
    s->host->fail(s->host->context, "out of memory");
    return GROWBENCH_OUT_OF_MEMORY;
  }
  for (k = 0; k < s->organ_count; ++k) { /* blossoms and kind-shaped leaves in turn, tinted by order */
    s->organ_shape[k] = k % 2 == 0 ? 0 : GROWBENCH_KIND_SHAPE;
    s->organ_tint[k].x = 1.0f;
    s->organ_tint[k].y = 0.5f + 0.5f * (float)(k % 3);
    s->organ_tint[k].z = 0.25f;
  }
  s->host->parallel_for(s->host->context, 0, s->node_count, 3, style_nodes, s);
  s->attributes[0].name = "height";
  s->attributes[0].components = 1;
  s->attributes[0].values = s->height;
  s->attributes[1].name = "Cd";
  s->attributes[1].components = 3;
  s->attributes[1].values = s->color;
#endif
#if TEST_PLUGIN_VARIANT == 9
  s->groups = (int32_t*)calloc(s->node_count + 1, sizeof(int32_t));
  if (!s->groups) {
    s->host->fail(s->host->context, "out of memory");
    return GROWBENCH_OUT_OF_MEMORY;
  }
  for (k = 0; k < s->node_count; ++k) s->groups[k] = k == 0 ? -1 : (int32_t)s->nodes[k].shoot;
  for (k = 0; k < 8; ++k) { /* a 4 x 2 image: red by column, green by row */
    s->pixels[4 * k] = (uint8_t)(60 * (k % 4));
    s->pixels[4 * k + 1] = (uint8_t)(120 * (k / 4));
    s->pixels[4 * k + 2] = 200;
    s->pixels[4 * k + 3] = 255;
  }
  s->decal.mesh = s->fault == 14 ? 99 : (int32_t)s->stats[1].value; /* fault=bad_decal: a mesh the scene lacks */
  s->decal.origin = s->scene->bounds_min;
  s->decal.u_axis.x = s->scene->bounds_max.x - s->scene->bounds_min.x;
  s->decal.v_axis.y = s->scene->bounds_max.y - s->scene->bounds_min.y;
  s->decal.width = 4;
  s->decal.height = 2;
  s->decal.rgba = s->pixels;
#endif
  return GROWBENCH_OK;
}

static int32_t plant(growbench_instance* instance, growbench_plant_view* out) {
  state* s = (state*)instance;
  memset(out, 0, sizeof(*out));
  if (s->fault == 11 && s->node_count > 1) s->nodes[0].parent = 1; /* a parent after its child */
  if (s->fault == 12 && s->node_count > 1) s->nodes[s->node_count - 1].position.y = NAN;
  out->nodes = s->nodes;
  out->node_count = s->node_count;
  out->organs = s->organs;
  out->organ_count = s->organ_count;
  if (s->organ_shape) {
    static const char* const shapes[] = {"blossom"};
    out->organ_shapes = shapes;
    out->organ_shape_count = 1;
    out->organ_shape = s->organ_shape;
    out->organ_tint = s->organ_tint;
    out->node_attributes = s->attributes;
    out->node_attribute_count = 2;
  }
#if TEST_PLUGIN_VARIANT == 9
  if (s->groups) {
    out->node_groups = s->groups;
    out->group_prefix = "stalk";
    out->decals = &s->decal;
    out->decal_count = 1;
  }
#endif
  return GROWBENCH_OK;
}

static uint32_t stats(growbench_instance* instance, const growbench_stat** out) {
  static growbench_stat one[1] = {{"steps", 0.0}};
#if TEST_PLUGIN_VARIANT == 9
  state* s = (state*)instance;
  s->stats[0].value = (double)s->steps;
  *out = s->stats;
  return s->stat_count;
#endif
  one[0].value = (double)((state*)instance)->steps;
  *out = one;
  return 1;
}

static void destroy(growbench_instance* instance) {
  state* s = (state*)instance;
  free(s->nodes);
  free(s->organs);
  free(s->tip);
  free(s->organ_shape);
  free(s->organ_tint);
  free(s->height);
  free(s->color);
  free(s->groups);
  free(s);
}

static const growbench_plugin kPlugin = {
#if TEST_PLUGIN_VARIANT == 2
    99u,
#elif TEST_PLUGIN_VARIANT == 8
    2u,
#elif TEST_PLUGIN_VARIANT == 9
    GROWBENCH_PLUGIN_ABI_VERSION,
#else
    1u, /* the tests' version-1 plugin: it fills only version 1's members */
#endif
    sizeof(growbench_plugin),
#if TEST_PLUGIN_VARIANT == 3
    "spacecol",
#elif TEST_PLUGIN_VARIANT == 8
    "line_v2",
#elif TEST_PLUGIN_VARIANT == 9
    "line_v3",
#else
    "line",
#endif
    "a straight stalk from every seed (a test plugin in C)",
    "1",
    kParams,
    3,
    kTestParams,
    1,
    create,
    start,
    step,
    finish,
    plant,
    NULL,
    stats,
    destroy};

#if TEST_PLUGIN_VARIANT == 1
GROWBENCH_PLUGIN_EXPORT const growbench_plugin* not_the_entry(void) {
  return &kPlugin;
}
#else
GROWBENCH_PLUGIN_EXPORT const growbench_plugin* growbench_plugin_entry(void) {
#if TEST_PLUGIN_VARIANT == 5
  signal(SIGSEGV, SIG_DFL);
  raise(SIGSEGV);
#elif TEST_PLUGIN_VARIANT == 6
  exit(0);
#elif TEST_PLUGIN_VARIANT == 7
  for (int fd = 0; fd < 1024; ++fd) close(fd);
  for (;;) pause();
#endif
  return &kPlugin;
}
#endif

/* Plugins for the loader's tests, written in plain C99 against plugin.h alone: one source, compiled once
 * per variant (TEST_PLUGIN_VARIANT, see CMakeLists.txt).
 *
 *  0 "line": a working plugin. From every seed, a straight stalk that climbs one `step` per growth step
 *    along the seed's direction until `length` nodes or a solid (host->inside) stops it; a leaf at each
 *    tip. Its `fault` parameter makes it crash, hang, exhaust memory or report errors, for the tests of
 *    how a suite records a misbehaving plugin (an exit() it never reports, a message of a megabyte, a flood of stderr,
 * a full disk), give NaN to the queries (nan_query), hand over an invalid plant (bad_parent, nan_node) or
 * one that differs from process to process (by_process).
 * 1 no entry point; 2 another ABI version; 3 a built-in's name; 4 a malformed parameter table;
 * 5 an entry() that crashes; 6 an entry() that calls exit(0); 7 an entry() that closes every descriptor and
 * waits forever. All of these declare ABI version 1 and check that they are given version 1's host table.
 * 8 "line_v2": the line in ABI version 2, with blossoms and tinted leaves (organ shapes and tints) and per-node
 * `height` and `Cd` attributes computed with the host's parallel_for. */
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

static const char* const kFaults[] = {"none",      "crash",      "hang",         "oom",       "fail",
                                      "input",     "exit3",      "long_message", "flood",     "disk_full",
                                      "nan_query", "bad_parent", "nan_node",     "by_process"};
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
} state;

#if TEST_PLUGIN_VARIANT == 8
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
#if TEST_PLUGIN_VARIANT == 8
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
  return GROWBENCH_OK;
}

static uint32_t stats(growbench_instance* instance, const growbench_stat** out) {
  static growbench_stat one[1] = {{"steps", 0.0}};
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
  free(s);
}

static const growbench_plugin kPlugin = {
#if TEST_PLUGIN_VARIANT == 2
    99u,
#elif TEST_PLUGIN_VARIANT == 8
    GROWBENCH_PLUGIN_ABI_VERSION,
#else
    1u, /* the tests' version-1 plugin: it fills only version 1's members */
#endif
    sizeof(growbench_plugin),
#if TEST_PLUGIN_VARIANT == 3
    "spacecol",
#elif TEST_PLUGIN_VARIANT == 8
    "line_v2",
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

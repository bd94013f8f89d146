/* growbench plugin ABI, version 3: the boundary between the growbench harness (the host) and a growth
 * algorithm built as a shared library (the plugin).
 *
 * C99, and nothing but plain data and function pointers cross it, so a plugin may be written in C, C++
 * or anything that can export a C function. docs/plugins.md is the reference; in short:
 *
 *  - The plugin exports one function, growbench_plugin_entry(), returning a table (growbench_plugin)
 *    whose first two members, abi_version and struct_size, keep their place in every version, so the
 *    host can tell a plugin of another version and say which.
 *  - The host drives growth: create, start, step until it returns 0 or a budget is met, finish, plant,
 *    stats, destroy. These are called from one thread at a time for one instance.
 *  - The plugin may call the host's table (growbench_host) from any thread: every query is safe for
 *    concurrent use, batched over arrays, and a pure function of its input.
 *  - Ownership: every pointer the host passes is the host's and lives as long as the call says; every
 *    pointer the plugin returns is the plugin's and must stay valid until the next call into the same
 *    instance (or, for the static table, until the library is unloaded). The host copies what it keeps.
 *
 * Versioning: adding a member at the end of a table or a new enum value that an older peer can refuse
 * keeps the version (struct_size tells which members exist); changing, removing or reordering anything
 * bumps GROWBENCH_PLUGIN_ABI_VERSION.
 */
#ifndef GROWBENCH_PLUGIN_H
#define GROWBENCH_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define GROWBENCH_PLUGIN_ABI_VERSION 3u
/* The oldest version a host of this version still loads. A plugin of an older version fills only the
 * members of growbench_plant_view its version had, and the host reads nothing more from it; it is given
 * the host table of its version (abi_version and struct_size say which). */
#define GROWBENCH_PLUGIN_ABI_OLDEST 1u

#if defined(_WIN32)
#define GROWBENCH_PLUGIN_EXPORT __declspec(dllexport)
#else
#define GROWBENCH_PLUGIN_EXPORT __attribute__((visibility("default")))
#endif

/* The name of the one symbol a plugin exports. */
#define GROWBENCH_PLUGIN_ENTRY_SYMBOL "growbench_plugin_entry"

/* ------------------------------------------------------------------ plain values */

typedef struct growbench_vec3 {
  float x, y, z;
} growbench_vec3;

/* Status codes the plugin's functions return. Before returning an error, the plugin calls
 * host->fail() with a message. */
typedef enum growbench_status {
  GROWBENCH_OK = 0,
  GROWBENCH_INPUT_ERROR = 1,  /* the parameters or the scene cannot work (the trial is invalid_input) */
  GROWBENCH_ERROR = 2,        /* anything else (the trial failed) */
  GROWBENCH_OUT_OF_MEMORY = 3 /* an allocation was refused (the trial ran out of memory) */
} growbench_status;

/* ------------------------------------------------------------------ the parameter table */

typedef enum growbench_param_type {
  GROWBENCH_PARAM_INT = 0,
  GROWBENCH_PARAM_REAL = 1,
  GROWBENCH_PARAM_BOOL = 2,
  GROWBENCH_PARAM_STRING = 3,
  GROWBENCH_PARAM_VEC3 = 4,
  GROWBENCH_PARAM_CHOICE = 5
} growbench_param_type;

/* One value of a parameter. Only the member of the parameter's type is read: `integer` (INT),
 * `real` (REAL), `boolean` (BOOL, 0 or 1), `text` (STRING and CHOICE), `vec3` (VEC3). */
typedef struct growbench_value {
  int64_t integer;
  double real;
  int32_t boolean;
  const char* text;
  double vec3[3];
} growbench_value;

/* One row of the parameter table, as `growbench list` prints it and `--set` validates it. */
typedef struct growbench_param {
  const char* name; /* [a-z0-9_]+, unique in the table */
  int32_t type;     /* growbench_param_type */
  growbench_value default_value;
  /* INT, REAL and each VEC3 component: the closed range allowed; -HUGE_VAL and HUGE_VAL (math.h)
   * for any finite value. Ignored for the other types. */
  double min, max;
  const char* unit;           /* "m", "deg", ... or NULL */
  const char* doc;            /* one line */
  const char* const* choices; /* CHOICE: the allowed values */
  uint32_t choice_count;      /* CHOICE: how many; the default must be one of them */
} growbench_param;

/* ------------------------------------------------------------------ the scene */

typedef struct growbench_mesh {
  const char* name;
  const growbench_vec3* vertices;
  uint64_t vertex_count;
  const uint32_t* triangles; /* 3 vertex indices per triangle */
  uint64_t triangle_count;
  int32_t climbable; /* plants may climb it (the ground is not) */
  int32_t solid;     /* closed: it has an inside */
} growbench_mesh;

typedef struct growbench_seed {
  growbench_vec3 position;
  growbench_vec3 direction;
  int32_t start_step; /* the step at which it starts growing (0: at once) */
} growbench_seed;

typedef enum growbench_shape_kind {
  GROWBENCH_SHAPE_BOX = 0,
  GROWBENCH_SHAPE_ELLIPSOID = 1,
  GROWBENCH_SHAPE_MESH = 2
} growbench_shape_kind;

/* An envelope or zone. Test whether a point is inside with host->inside_shape(). */
typedef struct growbench_shape {
  int32_t kind;                 /* growbench_shape_kind */
  growbench_vec3 min, max;      /* BOX; for the others, their bounds */
  growbench_vec3 center, radii; /* ELLIPSOID */
  growbench_mesh mesh;          /* MESH: a closed mesh */
} growbench_shape;

typedef enum growbench_zone_kind {
  GROWBENCH_ZONE_ATTRACT = 0,
  GROWBENCH_ZONE_REPEL = 1,
  GROWBENCH_ZONE_INCLUDE = 2,
  GROWBENCH_ZONE_EXCLUDE = 3
} growbench_zone_kind;

typedef struct growbench_zone {
  int32_t kind; /* growbench_zone_kind */
  growbench_shape shape;
  float strength;
} growbench_zone;

typedef struct growbench_light {
  int32_t point;            /* 0: the sun, 1: a point light */
  growbench_vec3 direction; /* sun: towards the light (not normalised) */
  growbench_vec3 position;  /* point light */
} growbench_light;

/* The scene a trial grows in. Units are metres, Y is up. Every array is the host's and lives until
 * the instance is destroyed. */
typedef struct growbench_scene {
  const char* name;
  const growbench_mesh* meshes;
  uint32_t mesh_count;
  const growbench_seed* seeds;
  uint32_t seed_count;
  growbench_light light;
  int32_t has_envelope;
  growbench_shape envelope; /* when has_envelope */
  const growbench_zone* zones;
  uint32_t zone_count;
  growbench_vec3 bounds_min, bounds_max; /* of the meshes */
  int32_t has_sdf;                       /* host->signed_distance() answers */
  float voxel_size;                      /* of the distance field */
} growbench_scene;

/* ------------------------------------------------------------------ the host's table */

typedef struct growbench_closest_hit {
  int32_t found; /* 0 when no surface lies within the distance asked */
  growbench_vec3 point;
  growbench_vec3 normal; /* unit face normal, outwards on closed meshes */
  float distance;
  uint32_t mesh, triangle;
} growbench_closest_hit;

typedef struct growbench_ray {
  growbench_vec3 origin;
  growbench_vec3 direction; /* need not be unit; t is in its units */
  float tmin, tmax;
} growbench_ray;

typedef struct growbench_ray_hit {
  int32_t hit;
  float t;
  growbench_vec3 point;
  growbench_vec3 normal; /* unit face normal as wound */
  uint32_t mesh, triangle;
} growbench_ray_hit;

typedef struct growbench_surface_sample {
  growbench_vec3 position, normal;
  uint32_t mesh, triangle;
} growbench_surface_sample;

/* Version 3: a point on a scene triangle, as closest_points, rays and sample_surface give them. */
typedef struct growbench_surface_point {
  growbench_vec3 point;
  uint32_t mesh, triangle;
} growbench_surface_point;

/* Version 3: the texture coordinates and surface frame at a growbench_surface_point. */
typedef struct growbench_surface_frame {
  int32_t found;               /* 0 when the mesh has no texture coordinates, an index is out of range or the
                                  point is not finite; nothing else is written then */
  float u, v;                  /* the corners' coordinates interpolated (barycentric); v points up the image */
  growbench_vec3 normal;       /* unit face normal as wound */
  growbench_vec3 dp_du, dp_dv; /* how far the point moves per unit of u and of v along the triangle */
} growbench_surface_frame;

typedef enum growbench_log_level { GROWBENCH_LOG_INFO = 0, GROWBENCH_LOG_WARNING = 1 } growbench_log_level;

/* The envelope's index for inside_shape(); zones are 0 .. zone_count - 1. */
#define GROWBENCH_ENVELOPE (-1)

/* What the host offers the plugin. `context` is passed back as the first argument of every function.
 * Every function here is safe to call from several threads at once unless it says otherwise. The
 * queries write `n` results to `out`, which the caller allocates. */
typedef struct growbench_host {
  uint32_t abi_version; /* GROWBENCH_PLUGIN_ABI_VERSION of the host */
  uint32_t struct_size; /* sizeof(growbench_host) in the host */
  void* context;
  uint32_t threads; /* the threads this trial may use (TBB inside the plugin obeys it already) */

  /* A line for the trial's log. */
  void (*log)(void* context, int32_t level, const char* message);
  /* The message of the error about to be returned (the first call of a step wins). */
  void (*fail)(void* context, const char* message);
  /* Nonzero once the trial's time limit has passed: a long step should return soon after. */
  int32_t (*cancelled)(void* context);

  /* Counter-based random bits from the trial's seed: a pure function of (stream, counter), the same
   * for any thread or call order. Equal to the built-ins' generator (core/random.hpp). */
  uint64_t (*random_bits)(void* context, uint64_t stream, uint64_t counter);

  /* The closest point on the meshes within max_distance (INFINITY for any); climbable_only: among
   * the climbable meshes only, when the scene marks any. */
  void (*closest_points)(void* context, const growbench_vec3* points, uint64_t n, float max_distance,
                         int32_t climbable_only, growbench_closest_hit* out);
  /* The first hit along each ray within (tmin, tmax). */
  void (*rays)(void* context, const growbench_ray* rays, uint64_t n, growbench_ray_hit* out);
  /* Whether anything lies along each ray within (tmin, tmax): 1 or 0. */
  void (*occluded)(void* context, const growbench_ray* rays, uint64_t n, uint8_t* out);
  /* Signed distance to the solids (negative inside) and its unit gradient (outwards): either array may
   * be NULL, and then only the other is computed. Returns GROWBENCH_ERROR, writing nothing, when the
   * scene has no field. */
  int32_t (*signed_distance)(void* context, const growbench_vec3* points, uint64_t n, float* distance,
                             growbench_vec3* gradient);
  /* Whether each point lies inside a solid (exact; the surface itself is outside): 1 or 0. */
  void (*inside)(void* context, const growbench_vec3* points, uint64_t n, uint8_t* out);
  /* Whether each point lies inside the envelope (GROWBENCH_ENVELOPE) or zone `shape`: 1 or 0. An index
   * the scene does not have gives 0 for every point. */
  void (*inside_shape)(void* context, int32_t shape, const growbench_vec3* points, uint64_t n, uint8_t* out);
  /* Area-weighted uniform samples on the climbable meshes (all when none is): sample i is a pure
   * function of (seed, first_index + i). */
  void (*sample_surface)(void* context, uint64_t seed, uint64_t first_index, uint64_t n, growbench_surface_sample* out);
  /* Whether each point sees the scene's light (a ray towards it, started `bias` along it): 1 or 0. */
  void (*light_visible)(void* context, const growbench_vec3* points, uint64_t n, float bias, uint8_t* out);

  /* Version 2. Calls body(user, chunk_begin, chunk_end) over disjoint chunks that cover [begin, end), on
   * at most `threads` threads at once (the trial's thread count), and returns when every chunk is done.
   * The chunks are those of halving [begin, end) until a piece holds at most `grain` indices (0: the
   * host's choice), so they depend only on (begin, end, grain), never on timing: results written per
   * index, or per chunk and combined in index order, are the same for any thread count. body must not
   * throw or longjmp out; it may call the queries above. */
  void (*parallel_for)(void* context, uint64_t begin, uint64_t end, uint64_t grain,
                       void (*body)(void* user, uint64_t chunk_begin, uint64_t chunk_end), void* user);

  /* Version 3. The texture coordinates of scene mesh `mesh` as its file gives them: corner k of triangle
   * t has (u, v) = (uvs[2 * i], uvs[2 * i + 1]) with i = uv_triangles[3 * t + k]; v points up the image
   * (the top row of an image is v = 1). Coordinates outside [0, 1] are kept as given. Returns 1, or 0 with
   * the arrays NULL and *uv_count 0 when the mesh has none or `mesh` is out of range. The arrays are the
   * host's and live until destroy(). */
  int32_t (*mesh_uvs)(void* context, uint32_t mesh, const float** uvs, uint64_t* uv_count,
                      const uint32_t** uv_triangles);
  /* The texture coordinates, face normal and tangents at each point (see growbench_surface_frame). */
  void (*surface_frames)(void* context, const growbench_surface_point* points, uint64_t n,
                         growbench_surface_frame* out);
} growbench_host;

/* ------------------------------------------------------------------ the plant */

typedef struct growbench_node {
  growbench_vec3 position;
  float radius;
  int32_t parent;      /* index of an earlier node, or -1 for a root */
  uint32_t order;      /* branch order: 0 on the main axis, +1 per lateral branch */
  uint32_t shoot;      /* nodes of one unbranched axis share it */
  uint32_t birth_step; /* the step at which it appeared */
} growbench_node;

typedef enum growbench_organ_kind {
  GROWBENCH_ORGAN_LEAF = 0,
  GROWBENCH_ORGAN_YOUNG_LEAF = 1,
  GROWBENCH_ORGAN_FLOWER = 2,
  GROWBENCH_ORGAN_BUD = 3
} growbench_organ_kind;

/* A leaf or flower. Its local frame: +Z along the blade from stalk to tip, +Y the upper side's normal;
 * `size` is the blade length. */
typedef struct growbench_organ {
  growbench_vec3 position;
  float orientation[4]; /* unit quaternion w, x, y, z taking the local frame to the world */
  float size;
  int32_t kind; /* growbench_organ_kind */
  int32_t node; /* the node it grows from, or -1 */
  float stamp[3];
} growbench_organ;

/* The plant as the plugin holds it. Every array is the plugin's and stays valid until the next call
 * into the instance. Polygon i has the vertices polygon_vertices[polygon_offsets[i] ..
 * polygon_offsets[i + 1]), so polygon_offsets has polygon_count + 1 entries (or is NULL when there are
 * no polygons). */
/* Version 2: a named value per node, carried to the PLY, glTF and skeleton files as the L-system's a()
 * attributes are. "Cd" with 3 components is the branches' colour (linear RGB, each in [0, 4]). */
typedef struct growbench_attribute {
  const char* name;    /* a letter or '_', then letters, digits and '_'; at most 64 bytes; unique */
  uint32_t components; /* 1 to 4 */
  const float* values; /* node_count * components, node by node; finite */
} growbench_attribute;

/* Version 3: an image laid over the scene's surfaces, as the built-in vines lays its texture. Renders draw
 * it over the surfaces' own material, and it stands for the plant there: a plant with decals is drawn by
 * them, not by its branches. The host writes it as a PNG beside the plant's meshes. */
#define GROWBENCH_PLANAR_DECAL (-1)
typedef struct growbench_decal {
  /* >= 0: the image follows that scene mesh's texture coordinates (the mesh must have them).
   * GROWBENCH_PLANAR_DECAL: image point (u, v) sits at origin + u * u_axis + v * v_axis and is projected
   * along u_axis x v_axis onto the climbable meshes. */
  int32_t mesh;
  growbench_vec3 origin, u_axis, v_axis;
  uint32_t width, height; /* 1 to 8192 each */
  const uint8_t* rgba;    /* width * height pixels of 4 bytes (sRGB, straight alpha), the top row first */
} growbench_decal;

/* The organ_shape of an organ that takes its kind's shape (leaf, blossom, bud). */
#define GROWBENCH_KIND_SHAPE 0xFFFFu

typedef struct growbench_plant_view {
  const growbench_node* nodes;
  uint64_t node_count;
  const growbench_organ* organs;
  uint64_t organ_count;
  const growbench_vec3* polygon_vertices;
  const uint64_t* polygon_offsets;
  uint64_t polygon_count;

  /* Version 2; each may be NULL (count 0). The shapes organs name: a built-in shape's name ("leaf",
   * "blossom", "half_bloom", "bud", with settings as `growbench list` shows) or an OBJ file's path. */
  const char* const* organ_shapes;
  uint32_t organ_shape_count;
  /* Per organ (organ_count entries): an index into organ_shapes, or GROWBENCH_KIND_SHAPE. */
  const uint16_t* organ_shape;
  /* Per organ: its colour as a factor on its shape's, each component in [0, 4]. */
  const growbench_vec3* organ_tint;
  /* Named per-node values. */
  const growbench_attribute* node_attributes;
  uint32_t node_attribute_count;

  /* Version 3; each may be NULL (count 0). Per node (node_count entries): its group, >= 0, or -1 for none,
   * as the L-system's g gives them. The branches of group g are their own part of the meshes, named
   * group_prefix followed by g (letters, digits and '_'; NULL or "" for "group"): the OBJ's g/usemtl pair
   * and the glTF's node that a material is given to in a modelling tool. */
  const int32_t* node_groups;
  const char* group_prefix;
  const growbench_decal* decals;
  uint32_t decal_count;
} growbench_plant_view;

typedef struct growbench_stat {
  const char* name;
  double value;
} growbench_stat;

/* ------------------------------------------------------------------ the plugin's table */

typedef struct growbench_instance growbench_instance; /* the plugin's, opaque to the host */

typedef struct growbench_plugin {
  uint32_t abi_version; /* GROWBENCH_PLUGIN_ABI_VERSION the plugin was built with: always first */
  uint32_t struct_size; /* sizeof(growbench_plugin) the plugin was built with: always second */
  const char* name;     /* [a-z0-9_]+; must not be a built-in's or another plugin's */
  const char* summary;  /* one line */
  const char* version;  /* the plugin's own version, recorded with its results */
  const growbench_param* params;
  uint32_t param_count;
  /* Assignments ("key=value") under which the plugin promises that no node enters a solid, at a size
   * that keeps the every-scene tests quick. May be empty. */
  const char* const* test_params;
  uint32_t test_param_count;

  /* A new instance, or NULL after host->fail(). `host` lives until destroy(). */
  growbench_instance* (*create)(const growbench_host* host);
  /* Prepares a run: `scene` lives until destroy(); `params` (param_count values, in the table's order,
   * already validated against it) only during the call. */
  int32_t (*start)(growbench_instance* instance, const growbench_scene* scene, const growbench_value* params,
                   uint64_t seed);
  /* One growth step: 1 to go on, 0 when growth has ended by itself, or minus a growbench_status. */
  int32_t (*step)(growbench_instance* instance);
  /* After the last step, before the plant is meshed (pipe radii, leaves). */
  int32_t (*finish)(growbench_instance* instance);
  /* The plant as it stands. */
  int32_t (*plant)(growbench_instance* instance, growbench_plant_view* out);
  /* The node and organ counts (what budgets and the growth curve read after every step), without
   * assembling the plant. May be NULL: the host then asks plant(). */
  void (*counts)(growbench_instance* instance, uint64_t* nodes, uint64_t* organs);
  /* Algorithm-specific figures for the record; `*out` is the plugin's. May be NULL. */
  uint32_t (*stats)(growbench_instance* instance, const growbench_stat** out);
  void (*destroy)(growbench_instance* instance);
} growbench_plugin;

/* The one function a plugin exports. It returns a table that lives until the library is unloaded. */
typedef const growbench_plugin* (*growbench_plugin_entry_fn)(void);
GROWBENCH_PLUGIN_EXPORT const growbench_plugin* growbench_plugin_entry(void);

#ifdef __cplusplus
}
#endif

#endif /* GROWBENCH_PLUGIN_H */

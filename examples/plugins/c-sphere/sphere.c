/* A delamesh oracle plugin written in C: a ball, meshed with patch 1 on its sphere.
 *
 * Configuration: "radius=R center=X,Y,Z" (both optional; defaults 1 and 0,0,0).
 * Build: cc -std=c99 -O2 -shared -fPIC -I include examples/plugins/c-sphere/sphere.c \
 *           -lm -o libdelamesh_c_sphere.so
 * Use:   delamesh mesh --plugin ./libdelamesh_c_sphere.so --plugin-config "radius=2"
 *
 * The oracle is immutable after create, so every query is thread-safe without locks, as the
 * contract in PLUGINS.md requires. Error messages live in a thread-local buffer. */

#include "delamesh_plugin.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(_MSC_VER)
#define EXPORT __declspec(dllexport)
#define THREAD_LOCAL __declspec(thread)
#else
#define EXPORT __attribute__((visibility("default")))
#define THREAD_LOCAL __thread
#endif

typedef struct Ball {
    DmVec3 center;
    double radius;
} Ball;

static THREAD_LOCAL char last_error_message[256];

static size_t copy_message(const char *message, char *buf, size_t cap) {
    size_t len = strlen(message);
    if (buf != NULL && cap > 0) {
        size_t n = len < cap - 1 ? len : cap - 1;
        memcpy(buf, message, n);
        buf[n] = '\0';
    }
    return len;
}

static int32_t fail(const char *message) {
    copy_message(message, last_error_message, sizeof last_error_message);
    return DM_ERROR;
}

static void *ball_create(const char *config, char *error, size_t error_cap) {
    Ball ball = {{0.0, 0.0, 0.0}, 1.0};
    const char *cursor = config != NULL ? config : "";
    char key[32];
    char value[128];
    int consumed = 0;
    while (sscanf(cursor, " %31[^= ]=%127s%n", key, value, &consumed) == 2) {
        cursor += consumed;
        if (strcmp(key, "radius") == 0) {
            char *end = NULL;
            ball.radius = strtod(value, &end);
            if (*end != '\0' || !(ball.radius > 0.0) || !isfinite(ball.radius)) {
                copy_message("radius must be a positive number", error, error_cap);
                return NULL;
            }
        } else if (strcmp(key, "center") == 0) {
            if (sscanf(value, "%lf,%lf,%lf", &ball.center.x, &ball.center.y, &ball.center.z) != 3) {
                copy_message("center must be x,y,z", error, error_cap);
                return NULL;
            }
        } else {
            char message[96];
            snprintf(message, sizeof message, "unknown key `%s` (known: radius, center)", key);
            copy_message(message, error, error_cap);
            return NULL;
        }
    }
    while (*cursor == ' ') {
        cursor++;
    }
    if (*cursor != '\0') {
        copy_message("expected key=value pairs", error, error_cap);
        return NULL;
    }
    Ball *handle = malloc(sizeof *handle);
    if (handle == NULL) {
        copy_message("out of memory", error, error_cap);
        return NULL;
    }
    *handle = ball;
    return handle;
}

static void ball_destroy(void *oracle) { free(oracle); }

static size_t ball_last_error(const void *oracle, char *buf, size_t cap) {
    (void)oracle;
    return copy_message(last_error_message, buf, cap);
}

static int32_t ball_bounding_box(const void *oracle, DmAabb *out) {
    const Ball *ball = oracle;
    if (out == NULL) {
        return fail("null output");
    }
    out->min = (DmVec3){ball->center.x - ball->radius, ball->center.y - ball->radius, ball->center.z - ball->radius};
    out->max = (DmVec3){ball->center.x + ball->radius, ball->center.y + ball->radius, ball->center.z + ball->radius};
    return DM_OK;
}

static int32_t ball_subdomains(const void *oracle, const DmVec3 *points, size_t n, uint32_t *out) {
    const Ball *ball = oracle;
    for (size_t i = 0; i < n; i++) {
        double dx = points[i].x - ball->center.x, dy = points[i].y - ball->center.y, dz = points[i].z - ball->center.z;
        out[i] = dx * dx + dy * dy + dz * dz < ball->radius * ball->radius ? 1 : 0;
    }
    return DM_OK;
}

/* Crossings of a + t d with the sphere for t in [0, t_max], sorted. */
static int32_t crossings(const Ball *ball, DmVec3 a, DmVec3 d, double t_max, DmSurfaceHit *out, size_t cap, size_t *len) {
    DmVec3 m = {a.x - ball->center.x, a.y - ball->center.y, a.z - ball->center.z};
    double qa = d.x * d.x + d.y * d.y + d.z * d.z;
    double qb = 2.0 * (m.x * d.x + m.y * d.y + m.z * d.z);
    double qc = m.x * m.x + m.y * m.y + m.z * m.z - ball->radius * ball->radius;
    double disc = qb * qb - 4.0 * qa * qc;
    DmSurfaceHit found[2];
    size_t n = 0;
    if (qa > 0.0 && disc > 0.0) {
        double root = sqrt(disc);
        /* The numerically stable pair of roots. */
        double q = -0.5 * (qb + (qb >= 0.0 ? root : -root));
        double t0 = q / qa, t1 = qc / q;
        double ts[2] = {t0 < t1 ? t0 : t1, t0 < t1 ? t1 : t0};
        for (int k = 0; k < 2; k++) {
            if (ts[k] >= 0.0 && ts[k] <= t_max) {
                double t = ts[k];
                found[n].point = (DmVec3){a.x + t * d.x, a.y + t * d.y, a.z + t * d.z};
                found[n].t = t;
                found[n].patch = 1;
                n++;
            }
        }
    }
    *len = n;
    if (n > cap) {
        return DM_BUFFER_TOO_SMALL;
    }
    memcpy(out, found, n * sizeof *found);
    return DM_OK;
}

static int32_t ball_segment_hits(const void *oracle, DmVec3 a, DmVec3 b, DmSurfaceHit *out, size_t cap, size_t *len) {
    DmVec3 d = {b.x - a.x, b.y - a.y, b.z - a.z};
    return crossings(oracle, a, d, 1.0, out, cap, len);
}

static int32_t ball_ray_hits(const void *oracle, DmVec3 origin, DmVec3 dir, DmSurfaceHit *out, size_t cap, size_t *len) {
    return crossings(oracle, origin, dir, INFINITY, out, cap, len);
}

static int32_t ball_initial_points(const void *oracle, DmSurfacePoint *out, size_t cap, size_t *len) {
    const Ball *ball = oracle;
    static const double directions[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    *len = 6;
    if (cap < 6) {
        return DM_BUFFER_TOO_SMALL;
    }
    for (int i = 0; i < 6; i++) {
        out[i].point = (DmVec3){ball->center.x + ball->radius * directions[i][0], ball->center.y + ball->radius * directions[i][1],
                                ball->center.z + ball->radius * directions[i][2]};
        out[i].patch = 1;
    }
    return DM_OK;
}

static const DmPluginV1 table = {
    .abi_version = DM_ABI_VERSION,
    .struct_size = sizeof(DmPluginV1),
    .name = "c-sphere",
    .kind = "implicit",
    .version = "1.0.0",
    .create = ball_create,
    .destroy = ball_destroy,
    .last_error = ball_last_error,
    .bounding_box = ball_bounding_box,
    .subdomains = ball_subdomains,
    .segment_hits = ball_segment_hits,
    .ray_hits = ball_ray_hits,
    .initial_points = ball_initial_points,
    .feature_curves = NULL, /* a sphere has no 1D features */
    .corners = NULL,
};

EXPORT const DmPluginV1 *delamesh_plugin_v1(void) { return &table; }

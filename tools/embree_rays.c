/* Traces the bounce rays that `bench_bvh --dump-rays DIR` writes through
 * Embree 3, one at a time (rtcIntersect1), on one thread: the figure that
 * Airlight's one-ray traversal is measured against.
 *
 *   apt-get install libembree-dev
 *   cc -O2 -o /tmp/embree_rays tools/embree_rays.c -lembree3 -lm
 *   cargo run --release -p airlight --example bench_bvh -- --dump-rays /tmp
 *   /tmp/embree_rays /tmp/bounce_in.bin [QUALITY 0|1|2] [PASSES] [DEVICE CONFIG]
 *
 * Prints the best pass's rays per second, the hits and the sum of their
 * distances (to compare with Airlight's). QUALITY is Embree's build
 * quality: 0 low, 1 medium, 2 high (default; Mitsuba 3 asks for high).
 * DEVICE CONFIG is Embree's, e.g. "verbose=2" for the tree's statistics.
 */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

/* Reads `count` items of `size` bytes or exits with a message. */
static void *read_items(FILE *f, size_t size, uint32_t count, const char *path) {
    void *items = malloc((size_t)size * count + 1);
    if (!items || fread(items, size, count, f) != count) {
        fprintf(stderr, "%s: file ends early (expected %u items of %zu bytes)\n", path, count, size);
        exit(1);
    }
    return items;
}

static uint32_t read_count(FILE *f, const char *path) {
    uint32_t n;
    if (fread(&n, 4, 1, f) != 1) {
        fprintf(stderr, "%s: file ends early (expected a count)\n", path);
        exit(1);
    }
    return n;
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s RAYS.bin [QUALITY] [PASSES] [DEVICE CONFIG]\n", argv[0]);
        return 2;
    }
    const char *path = argv[1];
    int quality = argc > 2 ? atoi(argv[2]) : 2;
    int passes = argc > 3 ? atoi(argv[3]) : 5;
    FILE *f = fopen(path, "rb");
    if (!f) {
        perror(path);
        return 1;
    }
    uint32_t vertices = read_count(f, path);
    float *positions = read_items(f, 12, vertices, path);
    uint32_t triangles = read_count(f, path);
    uint32_t *indices = read_items(f, 12, triangles, path);
    uint32_t count = read_count(f, path);
    float *rays = read_items(f, 24, count, path);
    fclose(f);

    RTCDevice device = rtcNewDevice(argc > 4 ? argv[4] : NULL);
    RTCScene scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(scene, quality == 2   ? RTC_BUILD_QUALITY_HIGH
                                   : quality == 1 ? RTC_BUILD_QUALITY_MEDIUM
                                                  : RTC_BUILD_QUALITY_LOW);
    RTCGeometry mesh = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    void *vb = rtcSetNewGeometryBuffer(mesh, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, vertices);
    memcpy(vb, positions, (size_t)vertices * 12);
    void *ib = rtcSetNewGeometryBuffer(mesh, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, triangles);
    memcpy(ib, indices, (size_t)triangles * 12);
    rtcCommitGeometry(mesh);
    rtcAttachGeometry(scene, mesh);
    rtcReleaseGeometry(mesh);
    double start = seconds();
    rtcCommitScene(scene);
    fprintf(stderr, "%u triangles, tree built in %.2f s\n", triangles, seconds() - start);

    double best = INFINITY, distances = 0;
    uint64_t hits = 0;
    for (int pass = 0; pass < passes; pass++) {
        struct RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        hits = 0;
        distances = 0;
        start = seconds();
        for (uint32_t i = 0; i < count; i++) {
            const float *r = rays + 6 * i;
            struct RTCRayHit q;
            q.ray.org_x = r[0], q.ray.org_y = r[1], q.ray.org_z = r[2];
            q.ray.dir_x = r[3], q.ray.dir_y = r[4], q.ray.dir_z = r[5];
            q.ray.tnear = 0.0f, q.ray.tfar = INFINITY, q.ray.time = 0.0f;
            q.ray.mask = -1, q.ray.flags = 0, q.ray.id = 0;
            q.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(scene, &context, &q);
            if (q.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
                hits++;
                distances += q.ray.tfar;
            }
        }
        double elapsed = seconds() - start;
        if (elapsed < best) best = elapsed;
    }
    printf("Embree, one ray at a time, 1 thread: %.3f M rays/s (best of %d passes), %llu of %u rays hit, distances sum to %.4f\n",
           count / best / 1e6, passes, (unsigned long long)hits, count, distances);
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    return 0;
}

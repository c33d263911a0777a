/* A C host of libbmlr: realizes one BML file at 60 frames a second on its own clock, prints
 * the feedback (JSON lines) on stdout as it comes, and writes the default character's pose of
 * every frame (time, then x y z w per joint) to POSES.txt if given. Then it shows what a host
 * sees of errors: a malformed block and a panic inside the library, on stderr.
 *
 *   cc -o host host.c -I../include -L<target>/debug -lbmlr && LD_LIBRARY_PATH=... ./host welcome.xml
 */
#include <stdio.h>
#include <stdlib.h>

#include "bmlr.h"

#define CHECK(call)                                                                  \
    do {                                                                             \
        bmlr_status s_ = (call);                                                     \
        if (s_ != BMLR_OK) {                                                         \
            fprintf(stderr, "host: %s: status %d: %s\n", #call, (int)s_, bmlr_last_error()); \
            return 1;                                                                \
        }                                                                            \
    } while (0)

static char *read_file(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = malloc((size_t)n + 1);
    if (text && fread(text, 1, (size_t)n, f) != (size_t)n) {
        free(text);
        text = NULL;
    }
    if (text) text[n] = '\0';
    fclose(f);
    return text;
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: host BLOCK.xml [POSES.txt]\n");
        return 2;
    }
    char *bml = read_file(argv[1]);
    if (!bml) {
        fprintf(stderr, "host: %s: cannot read it\n", argv[1]);
        return 2;
    }
    FILE *poses = argc > 2 ? fopen(argv[2], "w") : NULL;

    bmlr_realizer *r = NULL;
    CHECK(bmlr_new("{\"idle\": true}", &r));
    size_t joints = 0;
    CHECK(bmlr_joint_count(r, &joints));
    float *q = malloc(sizeof(float) * 4 * joints);
    CHECK(bmlr_perform(r, bml));

    char line[1 << 16];
    size_t len = 0;
    for (int k = 0;; k++) {
        double t = k / 60.0;
        CHECK(bmlr_tick(r, t));
        for (;;) {
            CHECK(bmlr_next_feedback(r, line, sizeof line, &len));
            if (len == 0) break;
            puts(line);
        }
        if (poses) {
            CHECK(bmlr_pose(r, NULL, q, 4 * joints));
            fprintf(poses, "%.6f", t);
            for (size_t i = 0; i < 4 * joints; i++) fprintf(poses, " %.9g", q[i]);
            fputc('\n', poses);
        }
        double at = 0;
        int has = 0;
        CHECK(bmlr_next_event(r, &at, &has));
        if (!has) break;
    }

    /* a malformed block: a status that is not BMLR_OK, and a sentence saying why */
    bmlr_status s = bmlr_perform(r, "<bml id=\"broken\"><gesture");
    fprintf(stderr, "malformed: status %d: %s\n", (int)s, bmlr_last_error());
    /* a panic inside the library: an error, not an abort */
    s = bmlr_debug_panic();
    fprintf(stderr, "panic: status %d: %s\n", (int)s, bmlr_last_error());
    /* and the realizer still works after both */
    CHECK(bmlr_tick(r, 1000.0));

    CHECK(bmlr_free(r));
    free(q);
    free(bml);
    if (poses) fclose(poses);
    return 0;
}

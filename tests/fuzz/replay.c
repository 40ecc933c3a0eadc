// SPDX-License-Identifier: MIT
// Runs fuzz inputs through a target without libFuzzer: each argument is a file or a directory
// of files (not recursive). Prints how many inputs ran; exit 0 unless one could not be read (a
// crash is a crash: the sanitizers or the signal end the run).
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "fuzz.h"

static unsigned long runs_;

static int run_file_(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        fprintf(stderr, "%s: cannot open\n", path);
        return 1;
    }
    static uint8_t buf[1u << 20];
    const size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    // A copy of exactly n bytes, so that ASan sees a read past the input's end.
    uint8_t *copy = malloc(n > 0u ? n : 1u);
    if (copy == NULL) {
        return 1;
    }
    memcpy(copy, buf, n);
    (void)LLVMFuzzerTestOneInput(copy, n);
    free(copy);
    runs_++;
    return 0;
}

int main(int argc, char **argv)
{
    int bad = 0;
    for (int i = 1; i < argc; i++) {
        struct stat st;
        if (stat(argv[i], &st) != 0) {
            fprintf(stderr, "%s: no such file or directory\n", argv[i]);
            bad = 1;
        } else if (S_ISDIR(st.st_mode)) {
            DIR *d = opendir(argv[i]);
            struct dirent *e;
            while (d != NULL && (e = readdir(d)) != NULL) {
                if (e->d_name[0] == '.') {
                    continue;
                }
                char path[4096];
                snprintf(path, sizeof path, "%s/%s", argv[i], e->d_name);
                bad |= run_file_(path);
            }
            if (d != NULL) {
                closedir(d);
            }
        } else {
            bad |= run_file_(argv[i]);
        }
    }
    printf("replayed %lu inputs\n", runs_);
    return bad || runs_ == 0u;
}

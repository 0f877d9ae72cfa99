/* fuzz_replay.c — a main for a harness without libFuzzer: feeds every file named on the command
 * line (a directory: each regular file in it, dot files skipped) to LLVMFuzzerTestOneInput, so the
 * corpus and every kept crasher are a plain ctest in each build (gcc, clang, ASan). A missing
 * directory is fine (no crashers yet); exit 1 when a file cannot be read. */
#include <dirent.h>
#include <string.h>
#include <sys/stat.h>

#include "sf_fuzz.h"

static int run_file(const char *const path)
{
    FILE *const f = fopen(path, "rb");
    if (f == NULL) {
        fprintf(stderr, "fuzz_replay: %s: cannot open\n", path);
        return 1;
    }
    size_t cap = 1u << 16, size = 0;
    uint8_t *buf = NULL;
    for (;;) {
        uint8_t *const bigger = realloc(buf, cap);
        if (bigger == NULL) {
            free(buf);
            fclose(f);
            return 1;
        }
        buf = bigger;
        size += fread(buf + size, 1, cap - size, f);
        if (size < cap) {
            break;
        }
        cap *= 2u;
    }
    const int bad = ferror(f);
    fclose(f);
    if (!bad) {
        (void)LLVMFuzzerTestOneInput(buf, size);
    }
    free(buf);
    return bad ? 1 : 0;
}

int main(const int argc, char **const argv)
{
    int status = 0;
    int files = 0;
    for (int i = 1; i < argc; i++) {
        struct stat st;
        if (stat(argv[i], &st) != 0) {
            continue;
        }
        if (!S_ISDIR(st.st_mode)) {
            status |= run_file(argv[i]);
            files++;
            continue;
        }
        DIR *const dir = opendir(argv[i]);
        if (dir == NULL) {
            return 1;
        }
        const struct dirent *e;
        while ((e = readdir(dir)) != NULL) {
            if (e->d_name[0] == '.') {
                continue;
            }
            char path[4096];
            snprintf(path, sizeof path, "%s/%s", argv[i], e->d_name);
            if (stat(path, &st) == 0 && S_ISREG(st.st_mode)) {
                status |= run_file(path);
                files++;
            }
        }
        closedir(dir);
    }
    printf("fuzz_replay: %d inputs\n", files);
    return status;
}

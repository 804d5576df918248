/*
 * test_interrupt.c - Ctrl-C during a hierarchical solve: the run stops cleanly, writes its
 * outputs with the solution so far, and exits with status 130.
 *
 * The tool solves the Cornell box at patch size 5 mm (78225 patches: about 14 s in a
 * Release build on 2 cores, far more under the sanitizers) with
 * RADIOSITY_PROGRESS=lines, so that progress comes as lines on a pipe. As soon as the
 * first "refine" line arrives (the first refinement pass is done, the Ctrl-C handler is
 * in place) the test sends SIGINT: there is no sleep and no timing, and the solve is far
 * from its end when the signal arrives. Then it checks:
 *   - the exit status 130, the warning, the --stats fields "interrupted": true and
 *     "converged": false, and that the first progress line shows the time left;
 *   - the solution file reads back, belongs to the scene and mesh, and holds finite,
 *     non-negative exitances, with the lights' own (pi Ke) at least on their patches;
 *   - the lit mesh (.obj) holds for each mesh vertex the radiance rad_reconstruct_vertices
 *     gives from that saved solution (1e-6 relative): both files are the same solution,
 *     complete; no temporary file is left;
 *   - `render --solution` of that file (with --direct solution) works (exit 0) and the image is lit;
 *   - `render` interrupted the same way exits 130 with its image written, lit.
 */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "testlib.h"

extern char **environ;

#define PATCH_SIZE "5"

/* Runs the tool with `words` (NULL-terminated, at most 16), SIGINT as soon as a stderr line contains `trigger`; returns
 * the wait status and the whole stderr in `text`. */
static int run_and_interrupt(const char *const words[], const char *trigger, char *text,
                             size_t size, char *first_trigger_line, size_t line_size)
{
    /* posix_spawn wants writable strings: copies of the words, NULL-terminated */
    enum { MOST_WORDS = 16, WORD_SIZE = 4200 };
    static char copies[MOST_WORDS][WORD_SIZE];
    char *argv[MOST_WORDS + 1];
    size_t count = 0;
    for (; words[count] && count < MOST_WORDS; count++) {
        snprintf(copies[count], WORD_SIZE, "%s", words[count]);
        argv[count] = copies[count];
    }
    argv[count] = NULL;
    int pipe_fd[2];
    if (pipe(pipe_fd) != 0)
        return -1;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, pipe_fd[1], STDERR_FILENO);
    posix_spawn_file_actions_addclose(&actions, pipe_fd[0]);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    pid_t pid;
    int spawned = posix_spawn(&pid, argv[0], &actions, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    close(pipe_fd[1]);
    if (spawned != 0) {
        close(pipe_fd[0]);
        return -1;
    }
    FILE *err = fdopen(pipe_fd[0], "r");
    size_t length = 0;
    bool sent = false;
    char line[1024];
    text[0] = 0;
    first_trigger_line[0] = 0;
    while (err && fgets(line, sizeof(line), err)) {
        if (length + strlen(line) < size) {
            strcpy(text + length, line);
            length += strlen(line);
        }
        if (!sent && strstr(line, trigger)) {
            snprintf(first_trigger_line, line_size, "%s", line);
            kill(pid, SIGINT);
            sent = true;
        }
    }
    if (err)
        fclose(err);
    else
        close(pipe_fd[0]);
    int status = -1;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    return status;
}

static void check_obj_against_solution(const char *obj_path, const rad_mesh *mesh,
                                       const rad_rgb *B)
{
    rad_rgb *L = calloc(mesh->vertex_count, sizeof(*L));
    rad_reconstruct_vertices(mesh, B, L);
    FILE *f = fopen(obj_path, "r");
    CHECK(f != NULL);
    uint32_t count = 0, bad = 0, faces = 0;
    char line[256];
    while (f && fgets(line, sizeof(line), f)) {
        double r, g, b;
        if (sscanf(line, "#radiance %lf %lf %lf", &r, &g, &b) == 3) {
            if (count < mesh->vertex_count) {
                const rad_rgb *e = &L[count];
                bad += fabs(r - e->r) > 1e-6 * fabs(e->r) + 1e-12 ||
                       fabs(g - e->g) > 1e-6 * fabs(e->g) + 1e-12 ||
                       fabs(b - e->b) > 1e-6 * fabs(e->b) + 1e-12;
            }
            count++;
        } else if (line[0] == 'f' && line[1] == ' ') {
            faces++;
        }
    }
    if (f)
        fclose(f);
    printf("lit mesh: %u vertices' radiance (%u differ from the saved solution's; %u added "
           "where regions split a common edge differently), %u faces\n",
           count, bad, count - mesh->vertex_count, faces);
    CHECK(count >= mesh->vertex_count); /* the mesh's, then the display's added ones */
    CHECK(bad == 0);
    CHECK(faces >= mesh->patch_count);
    free(L);
}

int main(void)
{
    setenv("RADIOSITY_PROGRESS", "lines", 1);
    char obj[4200], sol[4200], stats[4200];
    snprintf(obj, sizeof(obj), "%s", test_path("interrupted.obj"));
    snprintf(sol, sizeof(sol), "%s", test_path("interrupted.sol"));
    snprintf(stats, sizeof(stats), "%s", test_path("interrupted.json"));
    /* --direct solution: the lit mesh holds the patches' means, so it can be checked
     * against the saved solution alone (the light computed at the vertices is
     * test_lit_mesh's and test_contact_shadow's subject) */
    const char *words[] = {RAD_TOOL, "solve", "-o", obj, "--solver", "hierarchical",
                           "--patch-size", PATCH_SIZE, "--save-solution", sol, "--stats",
                           stats, "--direct", "solution", NULL};
    static char text[65536];
    char first[1024];
    int status = run_and_interrupt(words, "progress: refine", text, sizeof(text), first,
                                   sizeof(first));
    printf("stderr:\n%s", text);
    CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 130);
    CHECK(strstr(first, "left") != NULL); /* the time left */
    CHECK(strstr(text, "warning: interrupted: refinement and gathering stopped") != NULL);
    const char *json = test_read_text(stats);
    CHECK(strstr(json, "\"interrupted\": true") != NULL);
    CHECK(strstr(json, "\"converged\": false") != NULL);
    CHECK(test_count_files("interrupted.obj.tmp") == 0);
    CHECK(test_count_files("interrupted.sol.tmp") == 0);

    /* the saved solution: this scene and mesh, sound values */
    rad_error error;
    rad_scene *scene = NULL;
    rad_mesh *mesh = NULL;
    rad_solution *solution = NULL;
    CHECK(rad_scene_cornell_box(&scene, &error) == RAD_OK);
    CHECK(rad_mesh_build(scene, atof(PATCH_SIZE), &mesh, &error) == RAD_OK);
    CHECK(rad_solution_read(sol, &solution, &error) == RAD_OK);
    if (solution && mesh) {
        CHECK(rad_solution_match(solution, scene, mesh, &error) == RAD_OK);
        uint32_t bad = 0, lights = 0;
        for (uint32_t p = 0; p < solution->patch_count; p++) {
            const double *b = &solution->B[p].r;
            const double *ke = &scene->materials[mesh->patches[p].material].emission.r;
            for (int c = 0; c < 3; c++)
                bad += !isfinite(b[c]) || b[c] < 3.14159265 * ke[c] * (1 - 1e-12);
            lights += ke[0] > 0;
        }
        printf("solution: %u patches (%u of the light), %u values not finite or below pi Ke\n",
               solution->patch_count, lights, bad);
        CHECK(lights > 0);
        CHECK(bad == 0);
        check_obj_against_solution(obj, mesh, solution->B);
    }

    /* rendered from the saved solution (--direct solution here and below: the light at
     * each of the 80k patches' vertices, which the default computes, would take some 20 s
     * a render and is test_render_accuracy's subject, not this test's) */
    char arguments[8600];
    snprintf(arguments, sizeof(arguments), "render --solution '%s' -o from-solution.pfm "
             "--size 32x24 --direct solution", sol);
    int code = test_run_tool(arguments);
    CHECK(code == 0);
    rad_image *image = NULL;
    CHECK(rad_image_read(test_path("from-solution.pfm"), &image, &error) == RAD_OK);
    if (image) {
        double sum = 0;
        for (size_t k = 0; k < (size_t)image->width * image->height * 3; k++)
            sum += image->rgb[k];
        printf("render --solution: exit %d, mean value %.4f\n", code,
               sum / ((double)image->width * image->height * 3));
        CHECK(sum > 0);
        rad_image_destroy(image);
    }

    /* `render` the same way: exit 130 and the image of the solution so far, complete */
    char pfm[4200];
    snprintf(pfm, sizeof(pfm), "%s", test_path("interrupted.pfm"));
    const char *render_words[] = {RAD_TOOL, "render", "-o", pfm, "--size", "32x24",
                                  "--solver", "hierarchical", "--patch-size", PATCH_SIZE,
                                  "--direct", "solution", NULL};
    status = run_and_interrupt(render_words, "progress: refine", text, sizeof(text), first,
                               sizeof(first));
    printf("render stderr:\n%s", text);
    CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 130);
    CHECK(strstr(text, "warning: interrupted") != NULL);
    CHECK(test_count_files("interrupted.pfm.tmp") == 0);
    image = NULL;
    CHECK(rad_image_read(pfm, &image, &error) == RAD_OK);
    if (image) {
        CHECK(image->width == 32 && image->height == 24);
        double sum = 0;
        for (size_t k = 0; k < (size_t)image->width * image->height * 3; k++)
            sum += image->rgb[k];
        CHECK(sum > 0);
        rad_image_destroy(image);
    }
    rad_solution_destroy(solution);
    rad_mesh_destroy(mesh);
    rad_scene_destroy(scene);
    return test_finish("test_interrupt");
}

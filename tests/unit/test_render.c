/* The renderer, headless (EGL surfaceless on Mesa llvmpipe): a sphere covers a plausible share
 * of the frame, the lights shade it, the tool is visible, clear-coat looks different from
 * plain; and the telemetry chart: its reader names the bad line and keeps the contact flag,
 * the chart is not blank and draws the chatter panel's goal line when given the figure. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

/* Mesa's llvmpipe keeps a few allocations in JIT-compiled code that LeakSanitizer cannot see
 * into; leak checking is paused while the GL context exists (weak: absent without ASan). */
extern void __lsan_disable(void) __attribute__((weak));
extern void __lsan_enable(void) __attribute__((weak));

#include "host/mesh/mesh.h"
#include "host/render/camera.h"
#include "host/render/chatter.h"
#include "host/render/offscreen.h"
#include "host/render/plot.h"
#include "host/render/telemetry_log.h"

enum { W = 200, H = 200 };
static const float SPHERE_R_M = 0.03f;

typedef struct {
    offscreen_t o;
    mesh_t sphere;
    camera_t cam;
    uint8_t rgb[W * H * 3];
} fixture_t;

static void make_sphere(mesh_t *m, float r, int slices, int stacks)
{
    mesh_init(m);
    for (int j = 0; j <= stacks; j++) {
        const float th = (float)M_PI * (float)j / (float)stacks;
        for (int i = 0; i <= slices; i++) {
            const float ph = 2.0f * (float)M_PI * (float)i / (float)slices;
            const vec3_t n = vec3(sinf(th) * cosf(ph), cosf(th), -sinf(th) * sinf(ph));
            assert_int_equal(mesh_add_vertex(m, vec3_scale(n, r), n, NULL), ARGIL_OK);
        }
    }
    for (int j = 0; j < stacks; j++)
        for (int i = 0; i < slices; i++) {
            const uint32_t a = (uint32_t)(j * (slices + 1) + i), b = a + (uint32_t)slices + 1;
            assert_int_equal(mesh_add_triangle(m, a, b, a + 1), ARGIL_OK);
            assert_int_equal(mesh_add_triangle(m, a + 1, b, b + 1), ARGIL_OK);
        }
}

static int setup(void **state)
{
    fixture_t *f = calloc(1, sizeof(*f));
    if (f == NULL)
        return -1;
    if (__lsan_disable)
        __lsan_disable();
    char err[512] = "";
    if (offscreen_open(&f->o, RENDER_BACKEND_EGL, W, H, err, sizeof(err)) != ARGIL_OK) {
        fprintf(stderr, "test_render: %s\n", err);
        free(f);
        return -1;
    }
    make_sphere(&f->sphere, SPHERE_R_M, 48, 24);
    if (renderer_set_mesh(&f->o.renderer, &f->sphere) != ARGIL_OK)
        return -1;
    camera_frame(&f->cam, vec3(-SPHERE_R_M, -SPHERE_R_M, -SPHERE_R_M),
                 vec3(SPHERE_R_M, SPHERE_R_M, SPHERE_R_M));
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture_t *f = *state;
    offscreen_close(&f->o);
    mesh_free(&f->sphere);
    free(f);
    if (__lsan_enable)
        __lsan_enable();
    return 0;
}

static void render(fixture_t *f, render_scene_t *s)
{
    camera_matrices(&f->cam, (float)W / (float)H, s->view, s->proj);
    offscreen_render(&f->o, s, f->rgb);
}

static bool is_background(const uint8_t *p, const render_scene_t *s)
{
    const int r = (int)lroundf(s->background.x * 255.0f), g = (int)lroundf(s->background.y * 255.0f),
              b = (int)lroundf(s->background.z * 255.0f);
    return abs(p[0] - r) <= 2 && abs(p[1] - g) <= 2 && abs(p[2] - b) <= 2;
}

/* Mean luminance of the object's pixels in columns [x0, x1). */
static double mean_object_luma(const fixture_t *f, const render_scene_t *s, int x0, int x1)
{
    double sum = 0.0;
    size_t n = 0;
    for (int y = 0; y < H; y++)
        for (int x = x0; x < x1; x++) {
            const uint8_t *p = f->rgb + ((size_t)y * W + (size_t)x) * 3;
            if (!is_background(p, s)) {
                sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                n++;
            }
        }
    return n ? sum / (double)n : 0.0;
}

static void test_sphere_covers_plausible_share(void **state)
{
    fixture_t *f = *state;
    render_scene_t s;
    render_scene_default(&s);
    render(f, &s);
    size_t covered = 0;
    for (size_t i = 0; i < (size_t)W * H; i++)
        covered += !is_background(f->rgb + 3 * i, &s);
    const double share = (double)covered / (W * H);
    /* Its silhouette spans 65 % of the height: π · 0.325² ≈ 33 % of a square frame. */
    assert_true(share > 0.20 && share < 0.60);
    assert_true(fabs(share - M_PI * 0.325 * 0.325) < 0.05);
    /* The centre pixel is clay, the corners background. */
    assert_false(is_background(f->rgb + ((size_t)(H / 2) * W + W / 2) * 3, &s));
    assert_true(is_background(f->rgb, &s));
    assert_true(is_background(f->rgb + ((size_t)H * W - 1) * 3, &s));
}

static void test_lights_change_shading(void **state)
{
    fixture_t *f = *state;
    render_scene_t s;
    render_scene_default(&s);
    s.fill.rgb = vec3(0, 0, 0);
    s.key.dir = vec3(-1.0f, 0.0f, 0.3f); /* from the left */
    render(f, &s);
    const double left_lit_left = mean_object_luma(f, &s, 0, W / 2);
    const double left_lit_right = mean_object_luma(f, &s, W / 2, W);
    s.key.dir = vec3(1.0f, 0.0f, 0.3f); /* from the right */
    render(f, &s);
    const double right_lit_left = mean_object_luma(f, &s, 0, W / 2);
    /* The lit side is clearly brighter than the same side lit from the other side. */
    assert_true(left_lit_left > right_lit_left + 40.0);
    assert_true(left_lit_left > left_lit_right + 40.0);
    /* A fill light adds light everywhere. */
    s.fill.dir = vec3(-1.0f, 0.0f, 0.3f);
    s.fill.rgb = vec3(0.5f, 0.5f, 0.5f);
    render(f, &s);
    assert_true(mean_object_luma(f, &s, 0, W / 2) > right_lit_left + 20.0);
}

/* Pixels turned toward the tool's blue against a frame without it, in the given rectangle. */
static size_t count_bluer(const uint8_t *before, const uint8_t *after, int x0, int y0, int x1,
                          int y1)
{
    size_t n = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            const size_t i = ((size_t)y * W + (size_t)x) * 3;
            const int shift = ((int)after[i + 2] - after[i]) - ((int)before[i + 2] - before[i]);
            n += shift > 60;
        }
    return n;
}

static void test_tool_sphere_is_visible(void **state)
{
    fixture_t *f = *state;
    static uint8_t without[W * H * 3];
    render_scene_t s;
    render_scene_default(&s);
    render(f, &s);
    memcpy(without, f->rgb, sizeof(without));
    /* In front of the clay's centre, so it is drawn over it. */
    s.show_tool = true;
    s.tool_pos_m = vec3(0.0f, 0.0f, SPHERE_R_M + 0.01f);
    s.tool_radius_m = 0.008f;
    render(f, &s);
    /* Most of the 400 pixels around the centre turn blue; the corners do not change. */
    assert_true(count_bluer(without, f->rgb, W / 2 - 10, H / 2 - 10, W / 2 + 10, H / 2 + 10) >
                300);
    assert_int_equal(count_bluer(without, f->rgb, 0, 0, 20, 20), 0);
    /* Translucent: the clay shows through, so the centre keeps some of its red. */
    const uint8_t *p = f->rgb + ((size_t)(H / 2) * W + W / 2) * 3;
    assert_true(p[0] > 60);
    /* The force line (red) is drawn from the tool. */
    s.show_force = true;
    s.force_n = vec3(2.0f, 0.0f, 0.0f);
    s.force_m_per_n = 0.01f;
    render(f, &s);
    size_t red = 0;
    for (int x = W / 2 + 20; x < W - 5; x++) {
        const uint8_t *q = f->rgb + ((size_t)(H / 2) * W + (size_t)x) * 3;
        red += q[0] > 200 && q[1] < 120;
    }
    assert_true(red > 10);
}

static void test_clearcoat_differs_from_plain(void **state)
{
    fixture_t *f = *state;
    static uint8_t plain[W * H * 3];
    render_scene_t s;
    render_scene_default(&s);
    render(f, &s);
    memcpy(plain, f->rgb, sizeof(plain));
    s.mode = RENDER_MODE_CLEARCOAT;
    render(f, &s);
    double diff = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < (size_t)W * H; i++)
        if (!is_background(plain + 3 * i, &s)) {
            for (int k = 0; k < 3; k++)
                diff += abs((int)plain[3 * i + k] - (int)f->rgb[3 * i + k]);
            n++;
        }
    assert_true(n > 1000);
    assert_true(diff / (3.0 * (double)n) > 4.0); /* mean difference per channel, 0..255 */
}

static void write_file(const char *path, const char *text)
{
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fputs(text, fp);
    fclose(fp);
}

#define HEADER "time_s,x_mm,y_mm,z_mm,fx_n,fy_n,fz_n,force_n,state,tool,buttons,contact,sculpting\n"

/* Reading text as a telemetry.csv is refused with code, err holding needle, and no rows kept. */
static void expect_csv_error(telemetry_err_t code, const char *text, const char *needle)
{
    char path[] = "/tmp/argil-test-render-XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    write_file(path, text);
    telemetry_log_t log;
    char err[512] = "";
    assert_int_equal(telemetry_log_read(path, &log, err, sizeof(err)), code);
    if (strstr(err, needle) == NULL)
        fail_msg("error '%s' lacks '%s'", err, needle);
    assert_int_equal(log.n, 0);
    remove(path);
}

static void test_telemetry_errors_name_the_line(void **state)
{
    (void)state;
    expect_csv_error(TELEMETRY_ERR_EMPTY, "", "empty file");
    expect_csv_error(TELEMETRY_ERR_COLUMN, "time_s,x_mm\n1,2\n",
                     "line 1: the header has no 'y_mm'");
    expect_csv_error(TELEMETRY_ERR_NO_ROWS, HEADER, "no data rows");
    expect_csv_error(TELEMETRY_ERR_FIELDS,
                     HEADER "0.001,0,0,60,0,0,0,0,IDLE,0,0,0,0\n0.002,0,0,60,0,0\n",
                     "line 3: 6 fields where the header has 13");
    expect_csv_error(TELEMETRY_ERR_NUMBER, HEADER "0.001,0,0,6x,0,0,0,0,IDLE,0,0,0,0\n",
                     "line 2: z_mm is not a finite");
    expect_csv_error(TELEMETRY_ERR_NUMBER, HEADER "0.001,0,0,nan,0,0,0,0,IDLE,0,0,0,0\n",
                     "line 2: z_mm");
    /* Finite as a double but beyond a float (found by fuzz_telemetry). */
    expect_csv_error(TELEMETRY_ERR_NUMBER, HEADER "0.001,0,0,8e100,0,0,0,0,IDLE,0,0,0,0\n",
                     "line 2: z_mm is not a finite");
    expect_csv_error(TELEMETRY_ERR_TIME_BACKWARDS,
                     HEADER "0.002,0,0,1,0,0,0,0,IDLE,0,0,0,0\n0.001,0,0,1,0,0,0,0,IDLE,0,0,0,0\n",
                     "line 3: time_s goes backwards");
    expect_csv_error(TELEMETRY_ERR_STATE, HEADER "0.001,0,0,1,0,0,0,0,,0,0,0,0\n",
                     "line 2: state '' is empty");
    expect_csv_error(TELEMETRY_ERR_CONTACT,
                     HEADER "0.001,0,0,1,0,0,0,0,A,0,0,1,0\n0.002,0,0,1,0,0,0,0,A,0,0,2,0\n",
                     "line 3: contact is not 0 or 1: '2'");
    expect_csv_error(TELEMETRY_ERR_CONTACT, HEADER "0.001,0,0,1,0,0,0,0,A,0,0,,0\n",
                     "line 2: contact is not 0 or 1");
    expect_csv_error(TELEMETRY_ERR_CONTACT, HEADER "0.001,0,0,1,0,0,0,0,A,0,0,10,0\n",
                     "line 2: contact is not 0 or 1");
    expect_csv_error(TELEMETRY_ERR_STATES_MAX,
                     HEADER "0.001,0,0,1,0,0,0,0,A,0,0,0,0\n0.002,0,0,1,0,0,0,0,B,0,0,0,0\n"
                            "0.003,0,0,1,0,0,0,0,C,0,0,0,0\n0.004,0,0,1,0,0,0,0,D,0,0,0,0\n"
                            "0.005,0,0,1,0,0,0,0,E,0,0,0,0\n0.006,0,0,1,0,0,0,0,F,0,0,0,0\n"
                            "0.007,0,0,1,0,0,0,0,G,0,0,0,0\n0.008,0,0,1,0,0,0,0,H,0,0,0,0\n"
                            "0.009,0,0,1,0,0,0,0,I,0,0,0,0\n",
                     "line 10: more than 8 different states");
    telemetry_log_t log;
    char err[256];
    assert_int_equal(telemetry_log_read("/nonexistent/telemetry.csv", &log, err, sizeof(err)),
                     TELEMETRY_ERR_IO);
    /* A command reports IO and NOMEM as they are and every broken rule as PARSE. */
    assert_int_equal(telemetry_err_argil(TELEMETRY_OK), ARGIL_OK);
    assert_int_equal(telemetry_err_argil(TELEMETRY_ERR_IO), ARGIL_ERR_IO);
    assert_int_equal(telemetry_err_argil(TELEMETRY_ERR_NOMEM), ARGIL_ERR_NOMEM);
    assert_int_equal(telemetry_err_argil(TELEMETRY_ERR_EMPTY), ARGIL_ERR_PARSE);
    assert_int_equal(telemetry_err_argil(TELEMETRY_ERR_CONTACT), ARGIL_ERR_PARSE);
}

/* The contact column is kept when the header has it (chatter's first-contact rule), and a log
 * without it still reads, with no contact flags. */
static void test_telemetry_contact_column(void **state)
{
    (void)state;
    char path[] = "/tmp/argil-test-render-XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    write_file(path, HEADER "0.001,0,0,1,0,0,0,0,A,0,0,0,0\n0.002,0,0,1,0,0,1,1,A,0,0,1,0\n");
    telemetry_log_t log;
    char err[256] = "";
    assert_int_equal(telemetry_log_read(path, &log, err, sizeof(err)), ARGIL_OK);
    assert_non_null(log.contact);
    assert_int_equal(log.contact[0], 0);
    assert_int_equal(log.contact[1], 1);
    telemetry_log_free(&log);
    write_file(path, "time_s,x_mm,y_mm,z_mm,fx_n,fy_n,fz_n,force_n,state\n0.001,0,0,1,0,0,0,0,A\n");
    assert_int_equal(telemetry_log_read(path, &log, err, sizeof(err)), ARGIL_OK);
    assert_int_equal(log.n, 1);
    assert_null(log.contact);
    telemetry_log_free(&log);
    remove(path);
}

/* The longest horizontal run of pixels of colour r g b: a line across the plot. */
static int longest_run(const canvas_t *c, uint8_t r, uint8_t g, uint8_t b)
{
    int best = 0;
    for (int y = 0; y < c->height; y++) {
        int run = 0;
        for (int x = 0; x < c->width; x++) {
            const uint8_t *p = c->rgb + 3 * ((size_t)y * (size_t)c->width + (size_t)x);
            run = (p[0] == r && p[1] == g && p[2] == b) ? run + 1 : 0;
            best = run > best ? run : best;
        }
    }
    return best;
}

static void test_plot_draws_axes_and_series(void **state)
{
    (void)state;
    char path[] = "/tmp/argil-test-render-XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *fp = fdopen(fd, "w");
    assert_non_null(fp);
    fputs(HEADER, fp);
    for (int i = 0; i < 3000; i++) {
        const double t = 0.001 * (i + 1);
        fprintf(fp, "%.3f,0,0,%.3f,0,0,%.3f,%.3f,%s,0,0,0,0\n", t, 30.0 * cos(t * 3.0),
                sin(t * 5.0), fabs(sin(t * 5.0)), i < 200 ? "ARMED" : "ACTIVE");
    }
    fclose(fp);
    telemetry_log_t log;
    char err[256] = "";
    assert_int_equal(telemetry_log_read(path, &log, err, sizeof(err)), ARGIL_OK);
    remove(path);
    assert_int_equal(log.n, 3000);
    assert_int_equal(log.n_states, 2);
    canvas_t c;
    const rgb8_t white = {255, 255, 255};
    assert_int_equal(canvas_init(&c, 800, 500, white), ARGIL_OK);
    assert_int_equal(plot_telemetry(&log, &c, "test", NULL, NULL), ARGIL_OK);
    size_t red = 0, blue = 0, dark = 0;
    for (size_t i = 0; i < (size_t)800 * 500; i++) {
        const uint8_t *p = c.rgb + 3 * i;
        red += p[0] > 180 && p[1] < 80 && p[2] < 80;
        blue += p[2] > 150 && p[0] < 60;
        dark += p[0] < 60 && p[1] < 60 && p[2] < 60;
    }
    assert_true(red > 500);   /* the force curve */
    assert_true(blue > 500);  /* the z curve */
    assert_true(dark > 2000); /* frames, ticks, labels */
    /* With the chatter figure: its panel's goal line (green, 0 160 70) across the plot. */
    const int goal_before = longest_run(&c, 0, 160, 70);
    chatter_t ch;
    float *hp = calloc(log.n, sizeof(float));
    assert_non_null(hp);
    const chatter_trace_t tr = {hp, NULL};
    assert_int_equal(chatter_measure(&log, &ch, &tr), ARGIL_OK);
    assert_int_equal(plot_telemetry(&log, &c, "test", &ch, &tr), ARGIL_OK);
    free(hp);
    const int goal_after = longest_run(&c, 0, 160, 70);
    if (goal_before != 0 || goal_after < 600)
        fail_msg("goal line: %d pixels long without the chatter panel, %d with", goal_before,
                 goal_after);
    canvas_t small;
    assert_int_equal(canvas_init(&small, 100, 100, white), ARGIL_OK);
    assert_int_equal(plot_telemetry(&log, &small, NULL, NULL, NULL), ARGIL_ERR_ARG);
    canvas_free(&small);
    canvas_free(&c);
    telemetry_log_free(&log);
    assert_true(fabs(plot_nice_step(11.9, 8) - 1.0) < 1e-12);
    assert_true(fabs(plot_nice_step(3.3, 4) - 1.0) < 1e-12);
    assert_true(fabs(plot_nice_step(0.07, 4) - 0.02) < 1e-12);
}

static void test_offscreen_rejects_bad_size(void **state)
{
    (void)state;
    offscreen_t o;
    char err[256] = "";
    assert_int_equal(offscreen_open(&o, RENDER_BACKEND_EGL, 0, 10, err, sizeof(err)),
                     ARGIL_ERR_ARG);
    assert_non_null(strstr(err, "outside"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_telemetry_errors_name_the_line),
        cmocka_unit_test(test_telemetry_contact_column),
        cmocka_unit_test(test_plot_draws_axes_and_series),
        cmocka_unit_test(test_offscreen_rejects_bad_size),
        cmocka_unit_test(test_sphere_covers_plausible_share),
        cmocka_unit_test(test_lights_change_shading),
        cmocka_unit_test(test_tool_sphere_is_visible),
        cmocka_unit_test(test_clearcoat_differs_from_plain),
    };
    return cmocka_run_group_tests_name("render", tests, setup, teardown);
}

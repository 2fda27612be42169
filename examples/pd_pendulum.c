/* A PD controller in C holding the pendulum of examples/pd_pendulum.toml
 * at -0.5 rad through cdyn's C API (crates/cdyn-capi/include/cdyn.h):
 * every 10 steps (10 ms) it reads the link's angle, sets the torque input,
 * and steps on. Then it checks that a saved state, restored, repeats the
 * run bit for bit. Built and run by .ci/capi-test.sh:
 *
 *   cargo build -p cdyn-capi
 *   gcc -std=c99 -Wall -Werror examples/pd_pendulum.c -Icrates/cdyn-capi/include \
 *       -Ltarget/debug -lcdyn_capi -lm -o pd_pendulum
 *   LD_LIBRARY_PATH=target/debug ./pd_pendulum examples/pd_pendulum.toml
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cdyn.h"

#define KP 40.0
#define KD 6.0
#define TARGET (-0.5)
#define STEPS_PER_CONTROL 10

static int fail(const char *what) {
    fprintf(stderr, "pd_pendulum: %s: %s\n", what, cdyn_last_error());
    return 1;
}

/* Runs `periods` control periods from the simulation's state; `previous`
 * is the angle at the last period (the D term's difference). Leaves the
 * last angle in *angle. */
static int control(CdynSimulation *sim, size_t angle_index, int periods, double *previous, double *angle) {
    double outputs[16];
    size_t n = cdyn_output_count(sim);
    double dt = STEPS_PER_CONTROL * cdyn_step_size(sim);
    for (int k = 0; k < periods; k++) {
        if (cdyn_get_outputs(sim, outputs, n) != CDYN_STATUS_OK) return fail("outputs");
        *angle = outputs[angle_index];
        double tau = KP * (TARGET - *angle) - KD * (*angle - *previous) / dt;
        *previous = *angle;
        if (cdyn_set_input_by_name(sim, "tau", tau) != CDYN_STATUS_OK) return fail("set_input");
        if (cdyn_step(sim, STEPS_PER_CONTROL) != CDYN_STATUS_OK) return fail("step");
    }
    if (cdyn_get_outputs(sim, outputs, n) != CDYN_STATUS_OK) return fail("outputs");
    *angle = outputs[angle_index];
    return 0;
}

int main(int argc, char **argv) {
    const char *scenario = argc > 1 ? argv[1] : "examples/pd_pendulum.toml";
    CdynSimulation *sim = NULL;
    if (cdyn_create_from_file(scenario, &sim) != CDYN_STATUS_OK) return fail("create");
    size_t angle_index = cdyn_output_count(sim);
    for (size_t i = 0; i < cdyn_output_count(sim); i++)
        if (strcmp(cdyn_output_name(sim, i), "link.angle") == 0) angle_index = i;
    if (angle_index == cdyn_output_count(sim) || cdyn_output_count(sim) > 16) {
        fprintf(stderr, "pd_pendulum: the scenario has no output link.angle\n");
        return 1;
    }
    /* A bad call is an error code and a message, never a crash. */
    if (cdyn_set_input_by_name(sim, "tau", NAN) != CDYN_STATUS_ARGUMENT) return fail("NaN accepted");
    printf("refused as expected: %s\n", cdyn_last_error());

    double previous = 0.0, angle = 0.0;
    if (control(sim, angle_index, 100, &previous, &angle)) return 1;
    printf("t = %.3f s: angle %.6f rad\n", cdyn_time(sim), angle);
    CdynState *saved = NULL;
    if (cdyn_save_state(sim, &saved) != CDYN_STATUS_OK) return fail("save");
    double saved_previous = previous, first = 0.0, again = 0.0;
    if (control(sim, angle_index, 100, &previous, &first)) return 1;
    printf("t = %.3f s: angle %.17g rad (target %.1f)\n", cdyn_time(sim), first, TARGET);
    if (cdyn_restore_state(sim, saved) != CDYN_STATUS_OK) return fail("restore");
    previous = saved_previous;
    if (control(sim, angle_index, 100, &previous, &again)) return 1;
    cdyn_free_state(saved);
    cdyn_free(sim);
    if (memcmp(&first, &again, sizeof first) != 0) {
        fprintf(stderr, "pd_pendulum: restored run differs: %.17g vs %.17g\n", first, again);
        return 1;
    }
    if (fabs(first - TARGET) > 0.2) {
        fprintf(stderr, "pd_pendulum: the controller did not hold the angle: %.6f\n", first);
        return 1;
    }
    printf("restored run repeats to the bit\n");
    return 0;
}

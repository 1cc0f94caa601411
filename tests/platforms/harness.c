/* tests/platforms/harness.c: drives an FMU's shared library through the FMI 2.0 C API, the
 * call sequence of the Linux FMU tests, on any platform (issue 44). tests/platforms.sh builds it
 * natively for linux64, with mingw-w64 for win64 (run under wine) and with aarch64-linux-gnu-gcc
 * (run under qemu-aarch64), and compares what the three print.
 *
 *   harness LIBRARY RESOURCE_URI GUID DZ_VR DZ_PER_STEP STEPS OUTPUT_VR...
 *
 * Instantiates the library (fmi2CoSimulation, the resource URI), sets up the experiment, enters
 * and exits initialization, then for step k = 1..STEPS sets the input DZ_VR (the frame's dz) to
 * k * DZ_PER_STEP, does a step of 1 s and prints "step k vr value" for each OUTPUT_VR (%.17g).
 * After step STEPS-1 it takes the state (fmi2GetFMUstate), serializes it, frees it; after the last
 * step it deserializes it, sets it, repeats the last step and prints its outputs as "replay" lines,
 * then "replay identical 1" when they equal the last step's bit for bit. Ends with fmi2FreeInstance.
 * With HARNESS_SERIALIZE=0 in the environment the state is kept in memory instead of serialized
 * (an FMU without canSerializeFMUstate: the jack).
 * Exit status 0 when every call returned fmi2OK. No FMI headers needed: the few types are here. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
typedef HMODULE library_t;
static library_t open_library(const char *path) { return LoadLibraryA(path); }
static void *symbol(library_t l, const char *name) { return (void *)GetProcAddress(l, name); }
static void close_library(library_t l) { FreeLibrary(l); }
static const char *load_error(void) {
    static char text[64];
    snprintf(text, sizeof text, "LoadLibrary error %lu", (unsigned long)GetLastError());
    return text;
}
#else
#include <dlfcn.h>
typedef void *library_t;
static library_t open_library(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *symbol(library_t l, const char *name) { return dlsym(l, name); }
static void close_library(library_t l) { dlclose(l); }
static const char *load_error(void) { return dlerror(); }
#endif

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Boolean;
typedef char fmi2Byte;
typedef const char *fmi2String;
typedef int fmi2Status; /* fmi2OK = 0 */
enum { fmi2ModelExchange = 0, fmi2CoSimulation = 1 };

typedef struct {
    void (*logger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void (*stepFinished)(fmi2ComponentEnvironment, fmi2Status);
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list args;
    (void)env;
    fprintf(stderr, "[%s %d %s] ", instance ? instance : "", status, category ? category : "");
    va_start(args, message);
    vfprintf(stderr, message, args);
    va_end(args);
    fputc('\n', stderr);
}

typedef fmi2Component (*Instantiate)(fmi2String, int, fmi2String, fmi2String,
                                     const fmi2CallbackFunctions *, fmi2Boolean, fmi2Boolean);
typedef fmi2Status (*SetupExperiment)(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean,
                                      fmi2Real);
typedef fmi2Status (*Call)(fmi2Component);
typedef void (*FreeInstance)(fmi2Component);
typedef fmi2Status (*SetReal)(fmi2Component, const fmi2ValueReference *, size_t, const fmi2Real *);
typedef fmi2Status (*GetReal)(fmi2Component, const fmi2ValueReference *, size_t, fmi2Real *);
typedef fmi2Status (*DoStep)(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
typedef fmi2Status (*GetState)(fmi2Component, fmi2FMUstate *);
typedef fmi2Status (*SetState)(fmi2Component, fmi2FMUstate);
typedef fmi2Status (*FreeState)(fmi2Component, fmi2FMUstate *);
typedef fmi2Status (*StateSize)(fmi2Component, fmi2FMUstate, size_t *);
typedef fmi2Status (*Serialize)(fmi2Component, fmi2FMUstate, fmi2Byte *, size_t);
typedef fmi2Status (*Deserialize)(fmi2Component, const fmi2Byte *, size_t, fmi2FMUstate *);
typedef const char *(*GetString)(void);

static library_t library;
static int failures = 0;

static void *need(const char *name) {
    void *f = symbol(library, name);
    if (!f) {
        fprintf(stderr, "harness: the library exports no %s\n", name);
        exit(2);
    }
    return f;
}

static void check(fmi2Status status, const char *call) {
    if (status != 0) {
        fprintf(stderr, "harness: %s returned status %d\n", call, status);
        failures++;
    }
}

int main(int argc, char **argv) {
    if (argc < 8) {
        fprintf(stderr, "usage: %s LIBRARY RESOURCE_URI GUID DZ_VR DZ_PER_STEP STEPS OUTPUT_VR...\n",
                argv[0]);
        return 2;
    }
    const char *uri = argv[2], *guid = argv[3];
    fmi2ValueReference dz_vr = (fmi2ValueReference)strtoul(argv[4], NULL, 10);
    double dz_per_step = strtod(argv[5], NULL);
    int steps = atoi(argv[6]);
    size_t n = (size_t)(argc - 7);
    fmi2ValueReference *vrs = calloc(n, sizeof *vrs);
    fmi2Real *last = calloc(n, sizeof *last), *values = calloc(n, sizeof *values);
    for (size_t i = 0; i < n; i++) vrs[i] = (fmi2ValueReference)strtoul(argv[7 + i], NULL, 10);

    library = open_library(argv[1]);
    if (!library) {
        fprintf(stderr, "harness: cannot load %s: %s\n", argv[1], load_error());
        return 2;
    }
    printf("version %s types %s\n", ((GetString)need("fmi2GetVersion"))(),
           ((GetString)need("fmi2GetTypesPlatform"))());
    Instantiate instantiate = (Instantiate)need("fmi2Instantiate");
    SetReal set_real = (SetReal)need("fmi2SetReal");
    GetReal get_real = (GetReal)need("fmi2GetReal");
    DoStep do_step = (DoStep)need("fmi2DoStep");

    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2Component c = instantiate("harness", fmi2CoSimulation, guid, uri, &callbacks, 0, 0);
    if (!c) {
        fprintf(stderr, "harness: fmi2Instantiate returned NULL\n");
        return 1;
    }
    check(((SetupExperiment)need("fmi2SetupExperiment"))(c, 0, 0.0, 0.0, 0, 0.0),
          "fmi2SetupExperiment");
    check(((Call)need("fmi2EnterInitializationMode"))(c), "fmi2EnterInitializationMode");
    check(((Call)need("fmi2ExitInitializationMode"))(c), "fmi2ExitInitializationMode");

    const char *serialize_env = getenv("HARNESS_SERIALIZE");
    int serialize = !(serialize_env && strcmp(serialize_env, "0") == 0);
    fmi2Byte *serialized = NULL;
    size_t size = 0;
    fmi2FMUstate kept = NULL;
    for (int k = 1; k <= steps; k++) {
        if (k == steps && !serialize) { /* the state before the last step, kept */
            check(((GetState)need("fmi2GetFMUstate"))(c, &kept), "fmi2GetFMUstate");
        } else if (k == steps) { /* the state before the last step, serialized */
            fmi2FMUstate state = NULL;
            check(((GetState)need("fmi2GetFMUstate"))(c, &state), "fmi2GetFMUstate");
            check(((StateSize)need("fmi2SerializedFMUstateSize"))(c, state, &size),
                  "fmi2SerializedFMUstateSize");
            serialized = malloc(size);
            check(((Serialize)need("fmi2SerializeFMUstate"))(c, state, serialized, size),
                  "fmi2SerializeFMUstate");
            check(((FreeState)need("fmi2FreeFMUstate"))(c, &state), "fmi2FreeFMUstate");
            printf("state bytes %zu\n", size);
        }
        fmi2Real dz = k * dz_per_step;
        check(set_real(c, &dz_vr, 1, &dz), "fmi2SetReal");
        check(do_step(c, k - 1.0, 1.0, 1), "fmi2DoStep");
        check(get_real(c, vrs, n, last), "fmi2GetReal");
        for (size_t i = 0; i < n; i++) printf("step %d %u %.17g\n", k, vrs[i], last[i]);
    }
    if (serialized || kept) { /* back to before the last step (from the bytes), the step again */
        fmi2FMUstate state = kept;
        if (serialized)
            check(((Deserialize)need("fmi2DeSerializeFMUstate"))(c, serialized, size, &state),
                  "fmi2DeSerializeFMUstate");
        check(((SetState)need("fmi2SetFMUstate"))(c, state), "fmi2SetFMUstate");
        check(((FreeState)need("fmi2FreeFMUstate"))(c, &state), "fmi2FreeFMUstate");
        fmi2Real dz = steps * dz_per_step;
        check(set_real(c, &dz_vr, 1, &dz), "fmi2SetReal");
        check(do_step(c, steps - 1.0, 1.0, 1), "fmi2DoStep");
        check(get_real(c, vrs, n, values), "fmi2GetReal");
        for (size_t i = 0; i < n; i++) printf("replay %d %u %.17g\n", steps, vrs[i], values[i]);
        printf("replay identical %d\n", memcmp(values, last, n * sizeof *values) == 0);
        free(serialized);
    }
    ((FreeInstance)need("fmi2FreeInstance"))(c);
    close_library(library);
    printf("failures %d\n", failures);
    free(vrs);
    free(last);
    free(values);
    return failures ? 1 : 0;
}

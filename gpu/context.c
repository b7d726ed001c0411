/*
 * context.c - headless OpenGL 4.5 core contexts: EGL device, EGL surfaceless,
 * OSMesa (see context.h and docs/gl-backends.md).
 *
 * Process-wide state, guarded by one mutex:
 *   - a reference count per EGLDisplay: eglGetPlatformDisplayEXT returns the
 *     same display for the same device/platform and eglTerminate ends it for
 *     every context on it, so the display is terminated only when its last
 *     context goes;
 *   - the GL function table of gl.h, which belongs to the backend that loaded
 *     it last: a context remembers the table generation (gl.h) it loaded and
 *     lpv_gl_context_make_current reloads when the table changed since.
 *
 * GL drivers are kept mapped once loaded: libOSMesa is opened with
 * RTLD_NODELETE, and after the first eglInitialize the Mesa DRI driver that
 * libEGL_mesa loaded (e.g. swrast_dri.so, which pulls in libLLVM) is pinned
 * the same way. Otherwise every eglTerminate unloads the driver and LLVM and
 * the next context loads them again: slow, and the driver's static state (a
 * few hundred bytes per load) is lost each time, which LeakSanitizer reports
 * from an "<unknown module>" that no suppression can name. The table is cleared when the last context is destroyed, so a
 *     GL call after that faults at once instead of touching a dead driver.
 */
#define _GNU_SOURCE 1 /* dl_iterate_phdr, RTLD_NOLOAD */
#include "context.h"
#include "error.h"
#include "gl.h"

#define EGL_NO_X11 1 /* never pull in Xlib through eglplatform.h */
#include <EGL/egl.h>
#include <EGL/eglext.h>

/* osmesa.h includes <GL/gl.h>, whose prototypes clash with gl.h's table
 * (glClear would be both a function and a pointer). Only the OSMesa constants
 * and types are used (the library is opened with dlopen), so skip <GL/gl.h>
 * and give osmesa.h the two macros it needs from it; the GL types and enums
 * it names come from gl.h. */
#define __gl_h_ 1
#ifndef GLAPI
#define GLAPI extern
#endif
#ifndef GLAPIENTRY
#define GLAPIENTRY
#endif
#include <GL/osmesa.h>

#include <dlfcn.h>
#include <link.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- OSMesa entry points (from dlopen'd libOSMesa.so.8) ------------------- */
typedef OSMesaContext (*lpv_pfn_osmesa_create_attribs)(const int *attribs, OSMesaContext share);
typedef GLboolean (*lpv_pfn_osmesa_make_current)(OSMesaContext ctx, void *buffer, GLenum type,
                                                 GLsizei width, GLsizei height);
typedef void (*lpv_pfn_osmesa_destroy)(OSMesaContext ctx);
typedef OSMesaContext (*lpv_pfn_osmesa_get_current)(void);
typedef OSMESAproc (*lpv_pfn_osmesa_get_proc)(const char *name);

#define LPV_OSMESA_LIBRARY "libOSMesa.so.8"

struct lpv_gl_context {
    lpv_backend backend;
    int debug;
    unsigned table_gen; /* generation of the GL table this context loaded */

    /* EGL backends */
    EGLDisplay egl_dpy;
    EGLContext egl_ctx;
    EGLSurface egl_surf; /* a 1x1 pbuffer, only without EGL_KHR_surfaceless_context */

    /* OSMesa */
    void *osmesa_lib;
    OSMesaContext osmesa_ctx;
    lpv_pfn_osmesa_make_current osmesa_make_current;
    lpv_pfn_osmesa_destroy osmesa_destroy;
    lpv_pfn_osmesa_get_current osmesa_get_current;
    uint32_t osmesa_pixel; /* the 1x1 RGBA8 colour buffer OSMesaMakeCurrent needs */

    char renderer[256];
    char version[256];
};

/* ---- process-wide state ---------------------------------------------------- */
static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;

#define LPV_MAX_EGL_DISPLAYS 16
static struct {
    EGLDisplay dpy;
    int refs;
} g_displays[LPV_MAX_EGL_DISPLAYS];

static int g_live_contexts;    /* all backends */
static int g_live_egl_contexts;
/* OSMesaGetProcAddress of the open libOSMesa (it is opened with RTLD_NODELETE,
 * so the address stays valid for the whole process once set). */
static lpv_pfn_osmesa_get_proc g_osmesa_get_proc;
/* The lpvd context last made current on this thread (create, make_current). */
static _Thread_local lpv_gl_context *t_current;

/* ---- small helpers ---------------------------------------------------------- */

/* Appends to a NUL-terminated buffer, truncating silently. */
static void append_msg(char *buf, size_t size, const char *fmt, ...)
{
    if (!buf || !size)
        return;
    size_t len = strlen(buf);
    if (len + 1 >= size)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf + len, size - len, fmt, ap);
    va_end(ap);
}

/* 1 if the space-separated extension list contains exactly `name`. */
static int has_token(const char *list, const char *name)
{
    if (!list || !name)
        return 0;
    size_t n = strlen(name);
    const char *p = list;
    while ((p = strstr(p, name)) != NULL) {
        int starts = (p == list || p[-1] == ' ');
        int ends = (p[n] == '\0' || p[n] == ' ');
        if (starts && ends)
            return 1;
        p += n;
    }
    return 0;
}

static const char *egl_error_name(EGLint e)
{
    switch (e) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    default: return "unknown EGL error";
    }
}

/* ---- backend names -------------------------------------------------------- */
static const char *const k_backend_names[] = {
    [LPV_BACKEND_AUTO] = "auto",
    [LPV_BACKEND_EGL_DEVICE] = "egl-device",
    [LPV_BACKEND_EGL_SURFACELESS] = "egl-surfaceless",
    [LPV_BACKEND_OSMESA] = "osmesa",
};
#define LPV_BACKEND_COUNT ((int)(sizeof k_backend_names / sizeof k_backend_names[0]))

const char *lpv_backend_name(lpv_backend b)
{
    if ((int)b < 0 || (int)b >= LPV_BACKEND_COUNT)
        return "unknown";
    return k_backend_names[b];
}

int lpv_backend_parse(const char *name, lpv_backend *out)
{
    if (!name)
        return -1;
    for (int i = 0; i < LPV_BACKEND_COUNT; i++) {
        if (strcmp(name, k_backend_names[i]) == 0) {
            if (out)
                *out = (lpv_backend)i;
            return 0;
        }
    }
    return -1;
}

/* ---- keeping drivers mapped ------------------------------------------------- */
static int pin_driver_cb(struct dl_phdr_info *info, size_t size, void *data)
{
    (void)size;
    (void)data;
    const char *path = info->dlpi_name;
    if (!path || !path[0])
        return 0;
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t n = strlen(base);
    int is_dri = n > 7 && strcmp(base + n - 7, "_dri.so") == 0;
    int is_gallium = strncmp(base, "libgallium", 10) == 0;
    if (is_dri || is_gallium) {
        /* NOLOAD: only if already loaded; NODELETE: never unmapped again. The
         * flag sticks to the object, so the handle can be closed at once. */
        void *h = dlopen(path, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
        if (h)
            dlclose(h);
    }
    return 0;
}

static void pin_loaded_drivers(void)
{
    dl_iterate_phdr(pin_driver_cb, NULL);
}

/* ---- EGL display reference counts ----------------------------------------- */
/* Initializes dpy on its first reference. Returns 0, or -1 with reason. */
static int display_ref(EGLDisplay dpy, char *reason, size_t reason_size)
{
    int rc = -1;
    pthread_mutex_lock(&g_lock);
    int free_slot = -1;
    for (int i = 0; i < LPV_MAX_EGL_DISPLAYS; i++) {
        if (g_displays[i].refs > 0 && g_displays[i].dpy == dpy) {
            g_displays[i].refs++;
            rc = 0;
            goto out;
        }
        if (g_displays[i].refs == 0 && free_slot < 0)
            free_slot = i;
    }
    if (free_slot < 0) {
        lpv_error(reason, reason_size, "too many EGL displays in this process");
        goto out;
    }
    EGLint major = 0, minor = 0;
    if (!eglInitialize(dpy, &major, &minor)) {
        lpv_error(reason, reason_size, "eglInitialize failed (%s)", egl_error_name(eglGetError()));
        goto out;
    }
    g_displays[free_slot].dpy = dpy;
    g_displays[free_slot].refs = 1;
    pin_loaded_drivers();
    rc = 0;
out:
    pthread_mutex_unlock(&g_lock);
    return rc;
}

/* Terminates dpy when its last reference goes. */
static void display_unref(EGLDisplay dpy)
{
    pthread_mutex_lock(&g_lock);
    for (int i = 0; i < LPV_MAX_EGL_DISPLAYS; i++) {
        if (g_displays[i].refs > 0 && g_displays[i].dpy == dpy) {
            if (--g_displays[i].refs == 0) {
                eglTerminate(dpy);
                g_displays[i].dpy = EGL_NO_DISPLAY;
            }
            break;
        }
    }
    pthread_mutex_unlock(&g_lock);
}

/* ---- get-proc-address adapters for lpv_gl_load ------------------------------ */
static void *egl_get_proc(const char *name)
{
    return (void *)eglGetProcAddress(name);
}

static void *osmesa_get_proc(const char *name)
{
    return g_osmesa_get_proc ? (void *)g_osmesa_get_proc(name) : NULL;
}

static void *(*backend_get_proc(lpv_backend b))(const char *)
{
    return b == LPV_BACKEND_OSMESA ? osmesa_get_proc : egl_get_proc;
}

/* ---- GL debug output -------------------------------------------------------- */
static const char *debug_source_name(GLenum s)
{
    switch (s) {
    case GL_DEBUG_SOURCE_API: return "api";
    case GL_DEBUG_SOURCE_WINDOW_SYSTEM: return "window-system";
    case GL_DEBUG_SOURCE_SHADER_COMPILER: return "shader-compiler";
    case GL_DEBUG_SOURCE_THIRD_PARTY: return "third-party";
    case GL_DEBUG_SOURCE_APPLICATION: return "application";
    default: return "other";
    }
}

static const char *debug_type_name(GLenum t)
{
    switch (t) {
    case GL_DEBUG_TYPE_ERROR: return "error";
    case GL_DEBUG_TYPE_DEPRECATED_BEHAVIOR: return "deprecated";
    case GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR: return "undefined-behavior";
    case GL_DEBUG_TYPE_PORTABILITY: return "portability";
    case GL_DEBUG_TYPE_PERFORMANCE: return "performance";
    case GL_DEBUG_TYPE_MARKER: return "marker";
    case GL_DEBUG_TYPE_PUSH_GROUP: return "push-group";
    case GL_DEBUG_TYPE_POP_GROUP: return "pop-group";
    default: return "other";
    }
}

static const char *debug_severity_name(GLenum s)
{
    switch (s) {
    case GL_DEBUG_SEVERITY_HIGH: return "high";
    case GL_DEBUG_SEVERITY_MEDIUM: return "medium";
    case GL_DEBUG_SEVERITY_LOW: return "low";
    case GL_DEBUG_SEVERITY_NOTIFICATION: return "notification";
    default: return "?";
    }
}

static void APIENTRY debug_callback(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                                    const GLchar *message, const void *user)
{
    (void)user;
    fprintf(stderr, "lpvd: GL %s %s (%s, id %u): %.*s\n", debug_type_name(type), debug_severity_name(severity),
            debug_source_name(source), id, length >= 0 ? (int)length : (int)strlen(message), message);
}

static void install_debug_output(void)
{
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS); /* messages on the thread, at the call, that caused them */
    glDebugMessageCallback(debug_callback, NULL);
    glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, NULL, GL_TRUE);
    /* Notifications (buffer placement hints and the like) drown everything else. */
    glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DEBUG_SEVERITY_NOTIFICATION, 0, NULL, GL_FALSE);
}

/* ---- common part once a context is current ---------------------------------- */
static int finish_gl(lpv_gl_context *ctx, char *reason, size_t reason_size)
{
    char e[160] = "";
    pthread_mutex_lock(&g_lock);
    int loaded = lpv_gl_load(backend_get_proc(ctx->backend), e, sizeof e);
    ctx->table_gen = lpv_gl_table_generation();
    pthread_mutex_unlock(&g_lock);
    if (loaded != 0) {
        lpv_error(reason, reason_size, "GL function table: %s", e);
        return -1;
    }

    const char *renderer = (const char *)glGetString(GL_RENDERER);
    const char *version = (const char *)glGetString(GL_VERSION);
    snprintf(ctx->renderer, sizeof ctx->renderer, "%s", renderer ? renderer : "");
    snprintf(ctx->version, sizeof ctx->version, "%s", version ? version : "");
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    if (major == 0 && version) /* GL_MAJOR_VERSION needs 3.0; fall back to the string */
        sscanf(version, "%d.%d", &major, &minor);
    if (major * 100 + minor < 405) {
        lpv_error(reason, reason_size, "OpenGL %d.%d (\"%s\", renderer \"%s\") is below the required 4.5 core",
                (int)major, (int)minor, ctx->version, ctx->renderer);
        return -1;
    }
    if (!ctx->renderer[0]) {
        lpv_error(reason, reason_size, "glGetString(GL_RENDERER) returned nothing");
        return -1;
    }
    if (ctx->debug)
        install_debug_output();
    while (glGetError() != GL_NO_ERROR) {
    }
    return 0;
}

/* ---- EGL -------------------------------------------------------------------- */
/* EGL and OSMesa (both Mesa) share libglapi's per-thread dispatch, so
 * unbinding a context that EGL or OSMesa still counts as current can unbind
 * whatever lpvd context was made current after it. Put that one back. */
static void restore_current(const lpv_gl_context *leaving)
{
    if (t_current && t_current != leaving)
        lpv_gl_context_make_current(t_current);
}

static void egl_teardown(lpv_gl_context *ctx)
{
    if (ctx->egl_dpy == EGL_NO_DISPLAY)
        return;
    if (ctx->egl_ctx != EGL_NO_CONTEXT && eglGetCurrentContext() == ctx->egl_ctx) {
        eglMakeCurrent(ctx->egl_dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        restore_current(ctx);
    }
    if (ctx->egl_surf != EGL_NO_SURFACE)
        eglDestroySurface(ctx->egl_dpy, ctx->egl_surf);
    if (ctx->egl_ctx != EGL_NO_CONTEXT)
        eglDestroyContext(ctx->egl_dpy, ctx->egl_ctx);
    display_unref(ctx->egl_dpy);
    ctx->egl_surf = EGL_NO_SURFACE;
    ctx->egl_ctx = EGL_NO_CONTEXT;
    ctx->egl_dpy = EGL_NO_DISPLAY;
}

/* Creates a 4.5 core context on dpy and makes it current. On failure leaves
 * nothing behind (the display reference is dropped) and writes reason. */
static int egl_setup(lpv_gl_context *ctx, EGLDisplay dpy, char *reason, size_t reason_size)
{
    if (dpy == EGL_NO_DISPLAY) {
        lpv_error(reason, reason_size, "eglGetPlatformDisplayEXT failed (%s)", egl_error_name(eglGetError()));
        return -1;
    }
    if (display_ref(dpy, reason, reason_size) != 0)
        return -1;
    ctx->egl_dpy = dpy;

    if (!eglBindAPI(EGL_OPENGL_API)) {
        lpv_error(reason, reason_size, "eglBindAPI(EGL_OPENGL_API) failed (%s): no desktop OpenGL",
                egl_error_name(eglGetError()));
        goto fail;
    }
    const char *exts = eglQueryString(dpy, EGL_EXTENSIONS);
    int configless = has_token(exts, "EGL_KHR_no_config_context") || has_token(exts, "EGL_MESA_configless_context");
    int surfaceless = has_token(exts, "EGL_KHR_surfaceless_context");
    int create_ctx_khr = has_token(exts, "EGL_KHR_create_context");

    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!configless || !surfaceless) {
        static const EGLint config_attribs[] = {
            EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
            EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_NONE,
        };
        EGLint n = 0;
        if (!eglChooseConfig(dpy, config_attribs, &config, 1, &n) || n < 1) {
            lpv_error(reason, reason_size, "no pbuffer-capable OpenGL EGLConfig (%s)", egl_error_name(eglGetError()));
            goto fail;
        }
    }

    EGLint attribs[16];
    int a = 0;
    attribs[a++] = EGL_CONTEXT_MAJOR_VERSION;
    attribs[a++] = 4;
    attribs[a++] = EGL_CONTEXT_MINOR_VERSION;
    attribs[a++] = 5;
    attribs[a++] = EGL_CONTEXT_OPENGL_PROFILE_MASK;
    attribs[a++] = EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT;
    if (ctx->debug) {
        if (create_ctx_khr) {
            attribs[a++] = EGL_CONTEXT_FLAGS_KHR;
            attribs[a++] = EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR;
        } else {
            attribs[a++] = EGL_CONTEXT_OPENGL_DEBUG; /* EGL 1.5 */
            attribs[a++] = EGL_TRUE;
        }
    }
    attribs[a++] = EGL_NONE;

    ctx->egl_ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, attribs);
    if (ctx->egl_ctx == EGL_NO_CONTEXT) {
        lpv_error(reason, reason_size, "eglCreateContext(OpenGL 4.5 core) failed (%s)", egl_error_name(eglGetError()));
        goto fail;
    }
    if (!surfaceless) {
        static const EGLint pbuffer_attribs[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
        ctx->egl_surf = eglCreatePbufferSurface(dpy, config, pbuffer_attribs);
        if (ctx->egl_surf == EGL_NO_SURFACE) {
            lpv_error(reason, reason_size, "no EGL_KHR_surfaceless_context and eglCreatePbufferSurface failed (%s)",
                    egl_error_name(eglGetError()));
            goto fail;
        }
    }
    if (!eglMakeCurrent(dpy, ctx->egl_surf, ctx->egl_surf, ctx->egl_ctx)) {
        lpv_error(reason, reason_size, "eglMakeCurrent failed (%s)", egl_error_name(eglGetError()));
        goto fail;
    }
    if (finish_gl(ctx, reason, reason_size) != 0)
        goto fail;
    return 0;
fail:
    egl_teardown(ctx);
    return -1;
}

static int try_egl_device(lpv_gl_context *ctx, char *reason, size_t reason_size)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client) {
        lpv_error(reason, reason_size, "EGL client extensions unavailable (%s)", egl_error_name(eglGetError()));
        return -1;
    }
    if (!has_token(client, "EGL_EXT_device_enumeration") && !has_token(client, "EGL_EXT_device_base")) {
        lpv_error(reason, reason_size, "EGL lacks EGL_EXT_device_enumeration");
        return -1;
    }
    if (!has_token(client, "EGL_EXT_platform_device")) {
        lpv_error(reason, reason_size, "EGL lacks EGL_EXT_platform_device");
        return -1;
    }
    PFNEGLQUERYDEVICESEXTPROC query_devices = (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
    PFNEGLQUERYDEVICESTRINGEXTPROC query_device_string =
        (PFNEGLQUERYDEVICESTRINGEXTPROC)eglGetProcAddress("eglQueryDeviceStringEXT");
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!query_devices || !query_device_string || !get_platform_display) {
        lpv_error(reason, reason_size, "EGL device functions unavailable");
        return -1;
    }

    enum { MAX_DEVICES = 32 };
    EGLDeviceEXT devices[MAX_DEVICES];
    EGLint count = 0;
    if (!query_devices(MAX_DEVICES, devices, &count)) {
        lpv_error(reason, reason_size, "eglQueryDevicesEXT failed (%s)", egl_error_name(eglGetError()));
        return -1;
    }
    int software = 0;
    char tried[512] = "";
    for (EGLint i = 0; i < count; i++) {
        const char *dev_exts = query_device_string(devices[i], EGL_EXTENSIONS);
        if (has_token(dev_exts, "EGL_MESA_device_software")) {
            software++;
            continue;
        }
        const char *file = NULL;
        if (has_token(dev_exts, "EGL_EXT_device_drm"))
            file = query_device_string(devices[i], EGL_DRM_DEVICE_FILE_EXT);
        char why[256] = "";
        EGLDisplay dpy = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], NULL);
        if (egl_setup(ctx, dpy, why, sizeof why) == 0)
            return 0;
        append_msg(tried, sizeof tried, "%sdevice %d (%s): %s", tried[0] ? ", " : "", (int)i,
                   file ? file : "no DRM file", why);
    }
    if (tried[0])
        lpv_error(reason, reason_size, "no usable hardware EGL device (%d found, %d software skipped; %s)", (int)count,
                software, tried);
    else
        lpv_error(reason, reason_size, "no hardware EGL device (%d found, %d software skipped)", (int)count, software);
    return -1;
}

static int try_egl_surfaceless(lpv_gl_context *ctx, char *reason, size_t reason_size)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client) {
        lpv_error(reason, reason_size, "EGL client extensions unavailable (%s)", egl_error_name(eglGetError()));
        return -1;
    }
    if (!has_token(client, "EGL_MESA_platform_surfaceless")) {
        lpv_error(reason, reason_size, "EGL lacks EGL_MESA_platform_surfaceless");
        return -1;
    }
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!get_platform_display) {
        lpv_error(reason, reason_size, "eglGetPlatformDisplayEXT unavailable");
        return -1;
    }
    EGLDisplay dpy = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    return egl_setup(ctx, dpy, reason, reason_size);
}

/* ---- OSMesa ------------------------------------------------------------------ */
static void osmesa_teardown(lpv_gl_context *ctx)
{
    if (ctx->osmesa_ctx) {
        if (ctx->osmesa_get_current && ctx->osmesa_get_current() == ctx->osmesa_ctx) {
            ctx->osmesa_make_current(NULL, NULL, 0, 0, 0); /* unbind */
            restore_current(ctx);
        }
        ctx->osmesa_destroy(ctx->osmesa_ctx);
        ctx->osmesa_ctx = NULL;
    }
    if (ctx->osmesa_lib) {
        /* Opened with RTLD_NODELETE: this drops our reference but the code stays
         * mapped, as GL drivers (LLVM inside) do not survive being unloaded and
         * loaded again in one process. */
        dlclose(ctx->osmesa_lib);
        ctx->osmesa_lib = NULL;
    }
}

static int try_osmesa(lpv_gl_context *ctx, char *reason, size_t reason_size)
{
    dlerror();
    ctx->osmesa_lib = dlopen(LPV_OSMESA_LIBRARY, RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (!ctx->osmesa_lib) {
        const char *e = dlerror();
        lpv_error(reason, reason_size, "dlopen(%s) failed: %s", LPV_OSMESA_LIBRARY, e ? e : "unknown error");
        return -1;
    }
    lpv_pfn_osmesa_create_attribs create = (lpv_pfn_osmesa_create_attribs)dlsym(ctx->osmesa_lib,
                                                                              "OSMesaCreateContextAttribs");
    ctx->osmesa_make_current = (lpv_pfn_osmesa_make_current)dlsym(ctx->osmesa_lib, "OSMesaMakeCurrent");
    ctx->osmesa_destroy = (lpv_pfn_osmesa_destroy)dlsym(ctx->osmesa_lib, "OSMesaDestroyContext");
    ctx->osmesa_get_current = (lpv_pfn_osmesa_get_current)dlsym(ctx->osmesa_lib, "OSMesaGetCurrentContext");
    lpv_pfn_osmesa_get_proc get_proc = (lpv_pfn_osmesa_get_proc)dlsym(ctx->osmesa_lib, "OSMesaGetProcAddress");
    if (!create || !ctx->osmesa_make_current || !ctx->osmesa_destroy || !ctx->osmesa_get_current || !get_proc) {
        lpv_error(reason, reason_size, "%s lacks OSMesaCreateContextAttribs/MakeCurrent/DestroyContext/"
                "GetCurrentContext/GetProcAddress", LPV_OSMESA_LIBRARY);
        goto fail;
    }
    pthread_mutex_lock(&g_lock);
    g_osmesa_get_proc = get_proc;
    pthread_mutex_unlock(&g_lock);

    const int attribs[] = {
        OSMESA_FORMAT, OSMESA_RGBA,
        OSMESA_DEPTH_BITS, 0,
        OSMESA_STENCIL_BITS, 0,
        OSMESA_ACCUM_BITS, 0,
        OSMESA_PROFILE, OSMESA_CORE_PROFILE,
        OSMESA_CONTEXT_MAJOR_VERSION, 4,
        OSMESA_CONTEXT_MINOR_VERSION, 5,
        0,
    };
    ctx->osmesa_ctx = create(attribs, NULL);
    if (!ctx->osmesa_ctx) {
        lpv_error(reason, reason_size, "OSMesaCreateContextAttribs(OpenGL 4.5 core) failed");
        goto fail;
    }
    if (!ctx->osmesa_make_current(ctx->osmesa_ctx, &ctx->osmesa_pixel, GL_UNSIGNED_BYTE, 1, 1)) {
        lpv_error(reason, reason_size, "OSMesaMakeCurrent failed");
        goto fail;
    }
    if (finish_gl(ctx, reason, reason_size) != 0)
        goto fail;
    return 0;
fail:
    osmesa_teardown(ctx);
    return -1;
}

/* ---- public API ----------------------------------------------------------------- */
static int try_backend(lpv_gl_context *ctx, lpv_backend b, char *reason, size_t reason_size)
{
    ctx->backend = b;
    switch (b) {
    case LPV_BACKEND_EGL_DEVICE: return try_egl_device(ctx, reason, reason_size);
    case LPV_BACKEND_EGL_SURFACELESS: return try_egl_surfaceless(ctx, reason, reason_size);
    case LPV_BACKEND_OSMESA: return try_osmesa(ctx, reason, reason_size);
    default: lpv_error(reason, reason_size, "not a backend"); return -1;
    }
}

lpv_gl_context *lpv_gl_context_create(const lpv_gl_context_desc *desc, char *err, size_t err_size)
{
    lpv_error(err, err_size, "%s", "");
    lpv_backend wanted = desc ? desc->backend : LPV_BACKEND_AUTO;
    const char *origin = "";
    if ((int)wanted < 0 || (int)wanted >= LPV_BACKEND_COUNT) {
        lpv_error(err, err_size, "invalid backend %d in lpv_gl_context_desc", (int)wanted);
        return NULL;
    }
    if (wanted == LPV_BACKEND_AUTO) {
        const char *env = getenv("LPVD_GL_BACKEND");
        if (env && env[0]) {
            if (lpv_backend_parse(env, &wanted) != 0) {
                lpv_error(err, err_size,
                        "LPVD_GL_BACKEND=\"%s\" is not a backend (auto, egl-device, egl-surfaceless, osmesa)", env);
                return NULL;
            }
            origin = " (from LPVD_GL_BACKEND)";
        }
    }

    lpv_gl_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx) {
        lpv_error(err, err_size, "out of memory");
        return NULL;
    }
    ctx->debug = desc ? desc->debug : 0;
    ctx->egl_dpy = EGL_NO_DISPLAY;
    ctx->egl_ctx = EGL_NO_CONTEXT;
    ctx->egl_surf = EGL_NO_SURFACE;

    static const lpv_backend order[] = {LPV_BACKEND_EGL_DEVICE, LPV_BACKEND_EGL_SURFACELESS, LPV_BACKEND_OSMESA};
    int ok = 0;
    if (wanted == LPV_BACKEND_AUTO) {
        lpv_error(err, err_size, "no OpenGL 4.5 core context:");
        for (size_t i = 0; i < sizeof order / sizeof order[0] && !ok; i++) {
            char why[768] = "";
            if (try_backend(ctx, order[i], why, sizeof why) == 0)
                ok = 1;
            else
                append_msg(err, err_size, "%s %s: %s", i ? ";" : "", lpv_backend_name(order[i]), why);
        }
    } else {
        char why[768] = "";
        if (try_backend(ctx, wanted, why, sizeof why) == 0)
            ok = 1;
        else
            lpv_error(err, err_size, "no OpenGL 4.5 core context: %s%s: %s", lpv_backend_name(wanted), origin, why);
    }
    if (!ok) {
        free(ctx);
        pthread_mutex_lock(&g_lock);
        if (g_live_contexts == 0)
            lpv_gl_unload();
        pthread_mutex_unlock(&g_lock);
        return NULL;
    }
    lpv_error(err, err_size, "%s", "");
    t_current = ctx;
    pthread_mutex_lock(&g_lock);
    g_live_contexts++;
    if (ctx->backend != LPV_BACKEND_OSMESA)
        g_live_egl_contexts++;
    pthread_mutex_unlock(&g_lock);
    return ctx;
}

void lpv_gl_context_destroy(lpv_gl_context *ctx)
{
    if (!ctx)
        return;
    int release_egl_thread = 0;
    if (t_current == ctx)
        t_current = NULL;
    if (ctx->backend == LPV_BACKEND_OSMESA) {
        osmesa_teardown(ctx);
    } else {
        egl_teardown(ctx);
    }
    pthread_mutex_lock(&g_lock);
    g_live_contexts--;
    if (ctx->backend != LPV_BACKEND_OSMESA && --g_live_egl_contexts == 0)
        release_egl_thread = 1;
    if (g_live_contexts == 0)
        lpv_gl_unload();
    pthread_mutex_unlock(&g_lock);
    if (release_egl_thread)
        eglReleaseThread(); /* frees this thread's EGL state; no EGL context of ours is left */
    free(ctx);
}

int lpv_gl_context_make_current(lpv_gl_context *ctx)
{
    if (!ctx)
        return -1;
    if (ctx->backend == LPV_BACKEND_OSMESA) {
        if (!ctx->osmesa_make_current(ctx->osmesa_ctx, &ctx->osmesa_pixel, GL_UNSIGNED_BYTE, 1, 1))
            return -1;
    } else {
        if (!eglBindAPI(EGL_OPENGL_API))
            return -1;
        if (!eglMakeCurrent(ctx->egl_dpy, ctx->egl_surf, ctx->egl_surf, ctx->egl_ctx))
            return -1;
    }
    /* Another backend may have loaded its pointers into the table since. */
    pthread_mutex_lock(&g_lock);
    int rc = 0;
    if (ctx->table_gen != lpv_gl_table_generation()) {
        char e[160];
        if (lpv_gl_load(backend_get_proc(ctx->backend), e, sizeof e) == 0)
            ctx->table_gen = lpv_gl_table_generation();
        else
            rc = -1;
    }
    pthread_mutex_unlock(&g_lock);
    if (rc == 0)
        t_current = ctx;
    return rc;
}

lpv_backend lpv_gl_context_backend(const lpv_gl_context *ctx)
{
    return ctx ? ctx->backend : LPV_BACKEND_AUTO;
}

const char *lpv_gl_context_renderer(const lpv_gl_context *ctx)
{
    return ctx ? ctx->renderer : "";
}

const char *lpv_gl_context_version(const lpv_gl_context *ctx)
{
    return ctx ? ctx->version : "";
}

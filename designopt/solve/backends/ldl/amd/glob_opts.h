/* stand-in for OSQP's glob_opts.h: the C library's allocator */
#ifndef GLOB_OPTS_H
#define GLOB_OPTS_H
#include <stdlib.h>
#define c_malloc malloc
#define c_calloc calloc
#define c_realloc realloc
#define c_free free
#endif

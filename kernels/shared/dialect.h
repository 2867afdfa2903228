/* dialect.h: the only file that knows which language compiles the shared headers.
 * The shared math (element.h, node_rows.h, cg_rows.h, recenter.h, observation_gather.h) is
 * written once in the subset of C that C++, OpenCL C and Vulkan GLSL all accept; these macros
 * adapt the few places where they differ: SF_IN/SF_OUT/SF_INOUT array parameters (GLSL
 * passes arrays by value with a direction), SF_STRUCT(name) a struct type (OpenCL C needs the
 * keyword, GLSL forbids it), SF_INDEX_TYPE and SF_INDEX(x) the type that indexes a buffer
 * (size_t, or GLSL's 32-bit uint), SF_UINT(x) a conversion to uint, SF_ISFINITE (GLSL has no
 * isfinite), SF_LOAD(a, i) a read of a buffer that the kernel only reads (a[i]; in a Vulkan
 * shader compiled with SF_TEXEL_READS a texel fetch, kernels/vulkan/ensemble_layout.h). */
#ifndef SIGMAFEM_DIALECT_H
#define SIGMAFEM_DIALECT_H

#if defined(__cplusplus) /* CPU reference; a test may predefine SF_REAL float */
#  ifndef SF_REAL
#    define SF_REAL double
#  endif
#  define SF_FN inline
#  define SF_SQRT(x) std::sqrt(x)
#  define SF_ISFINITE(x) std::isfinite(x)
#  define SF_IN(n, N) const SF_REAL n[N]
#  define SF_OUT(n, N) SF_REAL n[N]
#  define SF_INOUT(n, N) SF_REAL n[N]
#  define SF_LIT(x) static_cast<SF_REAL>(x)
#  define SF_UNROLL
#  define SF_STRUCT(name) name
#  define SF_INDEX_TYPE std::size_t
#  define SF_INDEX(x) static_cast<std::size_t>(x)
#  define SF_UINT(x) static_cast<unsigned int>(x)
#  define SF_LOAD(a, i) (a)[i]
#  define SF_SELECT(cond, a, b) ((cond) ? (a) : (b))
#  define SF_NONZERO(x) ((x) != SF_LIT(0.0))
#  define SF_POSITIVE(x) ((x) > SF_LIT(0.0))
#  define SF_BOTH_ZERO(a, b) ((a) == SF_LIT(0.0) && (b) == SF_LIT(0.0))
typedef unsigned int uint;
#elif defined(__OPENCL_VERSION__) /* OpenCL C on PoCL or a GPU driver */
#  ifndef SF_REAL
#    define SF_REAL float
#  endif
#  define SF_FN static inline __attribute__((always_inline))
#  define SF_SQRT(x) sqrt(x)
#  define SF_ISFINITE(x) isfinite(x)
#  define SF_IN(n, N) const SF_REAL n[N]
#  define SF_OUT(n, N) SF_REAL n[N]
#  define SF_INOUT(n, N) SF_REAL n[N]
#  define SF_LIT(x) ((SF_REAL)(x))
/* Fully unrolled fixed-size loops turn the small private arrays into registers, which is
 * what lets PoCL vectorise across work-items (ARCHITECTURE.md: 3e7 -> 1.5e8 element-
 * iterations per second on the 2-core machine). */
#  define SF_UNROLL _Pragma("unroll")
#  define SF_STRUCT(name) struct name
#  define SF_INDEX_TYPE size_t
#  define SF_INDEX(x) ((size_t)(x))
#  define SF_UINT(x) ((uint)(x))
#  define SF_LOAD(a, i) (a)[i]
#  define SF_SELECT(cond, a, b) ((cond) ? (a) : (b))
#  define SF_NONZERO(x) ((x) != SF_LIT(0.0))
#  define SF_POSITIVE(x) ((x) > SF_LIT(0.0))
#  define SF_BOTH_ZERO(a, b) ((a) == SF_LIT(0.0) && (b) == SF_LIT(0.0))
#elif defined(VULKAN) /* GLSL through glslang for Vulkan */
#  ifndef SF_REAL
#    define SF_REAL float
#  endif
#  define SF_FN
#  define SF_SQRT(x) sqrt(x)
#  define SF_ISFINITE(x) (!isinf(x) && !isnan(x))
#  define SF_IN(n, N) in SF_REAL n[N]
#  define SF_OUT(n, N) out SF_REAL n[N]
#  define SF_INOUT(n, N) inout SF_REAL n[N]
#  define SF_LIT(x) SF_REAL(x)
#  define SF_UNROLL
#  define SF_STRUCT(name) name
#  define SF_INDEX_TYPE uint
#  define SF_INDEX(x) uint(x)
#  define SF_UINT(x) uint(x)
#  if defined(SF_TEXEL_READS)
#    define SF_LOAD(a, i) sf_texel(a, uint(i))
#  else
#    define SF_LOAD(a, i) a[i]
#  endif
/* The shared math's choices (SF_SELECT(cond, a, b) with SF_NONZERO, SF_POSITIVE, SF_BOTH_ZERO
 * conditions): ternaries, or per component where SF_REAL is a vec4 of sigma points
 * (kernels/vulkan/sigma_quads.h). */
#  if defined(SF_SIGMA_QUADS)
#    define SF_SELECT(cond, a, b) mix((b), (a), (cond))
#    define SF_NONZERO(x) notEqual((x), SF_LIT(0.0))
#    define SF_POSITIVE(x) greaterThan((x), SF_LIT(0.0))
/* Per component: both zero (node_rows.h's placeholder mass). */
#    define SF_BOTH_ZERO(a, b) \
      notEqual(uvec4(equal((a), SF_LIT(0.0))) & uvec4(equal((b), SF_LIT(0.0))), uvec4(0u))
#  else
#    define SF_SELECT(cond, a, b) ((cond) ? (a) : (b))
#    define SF_NONZERO(x) ((x) != SF_LIT(0.0))
#    define SF_POSITIVE(x) ((x) > SF_LIT(0.0))
#    define SF_BOTH_ZERO(a, b) ((a) == SF_LIT(0.0) && (b) == SF_LIT(0.0))
#  endif
#else
#  error "dialect.h: expected C++, OpenCL C or Vulkan GLSL"
#endif

#endif /* SIGMAFEM_DIALECT_H */

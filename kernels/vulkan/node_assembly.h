/* node_assembly.h: the storage buffers that every node-side shader reads (node_assembly.comp,
 * conjugate_gradient.comp's cg_start) at the same bindings; the rows themselves are
 * kernels/shared/node_rows.h, as in OpenCL. */
#ifndef SIGMAFEM_VULKAN_NODE_ASSEMBLY_H
#define SIGMAFEM_VULKAN_NODE_ASSEMBLY_H

#include "ensemble_layout.h"
#include "node_rows.h"
#if defined(SF_SIGMA_QUADS)
#  include "sigma_quads.h"
#endif

SF_READ_REALS(SF_NODE_CONSTANTS, c)
SF_READ_INTS(SF_NODE_INCIDENCE_OFFSETS, incidence_offsets)
SF_READ_INTS(SF_NODE_INCIDENCE, incidence)
SF_READ_INTS(SF_NODE_LIGAMENT_OFFSETS, ligament_offsets)
SF_READ_INTS(SF_NODE_LIGAMENT_OF_NODE, ligament_of_node)
#if defined(SF_SIGMA_QUADS) /* node_assembly.comp's quad form: sigma_quads.h */
SF_READ_QUADS(SF_NODE_LIGAMENT_K, ligament_k)
#else
SF_READ_REALS(SF_NODE_LIGAMENT_K, ligament_k)
#endif
SF_READ_REALS(SF_NODE_CONTROL_K, control_k)
SF_READ_REALS(SF_NODE_MASS, mass)

/* The spring on node n for sigma point s (or quad s of S / 4), from the buffers above. */
#if defined(SF_SIGMA_QUADS)
#  define SF_SPRING_OF(n, q, Q, spring) \
    SF_NODE_SPRING_QUADS(ligament_offsets, ligament_of_node, ligament_k, control_k, n, q, Q, spring)
#else
#  define SF_SPRING_OF(n, s, S, spring) \
    SF_NODE_SPRING(ligament_offsets, ligament_of_node, ligament_k, control_k, n, s, S, spring)
#endif

#endif /* SIGMAFEM_VULKAN_NODE_ASSEMBLY_H */

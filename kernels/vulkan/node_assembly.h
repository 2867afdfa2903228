/* node_assembly.h: the storage buffers that every node-side shader reads (node_assembly.comp,
 * conjugate_gradient.comp's cg_start) at the same bindings; the rows themselves are
 * kernels/shared/node_rows.h, as in OpenCL. */
#ifndef SIGMAFEM_VULKAN_NODE_ASSEMBLY_H
#define SIGMAFEM_VULKAN_NODE_ASSEMBLY_H

#include "ensemble_layout.h"
#include "node_rows.h"

layout(std430, binding = SF_NODE_CONSTANTS) restrict readonly buffer C { real c[]; };
layout(std430, binding = SF_NODE_INCIDENCE_OFFSETS) restrict readonly buffer IncidenceOffsets { int incidence_offsets[]; };
layout(std430, binding = SF_NODE_INCIDENCE) restrict readonly buffer Incidence { int incidence[]; };
layout(std430, binding = SF_NODE_LIGAMENT_OFFSETS) restrict readonly buffer LigamentOffsets { int ligament_offsets[]; };
layout(std430, binding = SF_NODE_LIGAMENT_OF_NODE) restrict readonly buffer LigamentOfNode { int ligament_of_node[]; };
layout(std430, binding = SF_NODE_LIGAMENT_K) restrict readonly buffer LigamentK { real ligament_k[]; };
layout(std430, binding = SF_NODE_CONTROL_K) restrict readonly buffer ControlK { real control_k[]; };
layout(std430, binding = SF_NODE_MASS) restrict readonly buffer Mass { real mass[]; };

/* The spring on node n for sigma point s, from the buffers above. */
#define SF_SPRING_OF(n, s, S, spring) \
  SF_NODE_SPRING(ligament_offsets, ligament_of_node, ligament_k, control_k, n, s, S, spring)

#endif /* SIGMAFEM_VULKAN_NODE_ASSEMBLY_H */

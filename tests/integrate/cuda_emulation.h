/* A CPU stand-in for a CUDA launch (test fixture): the ensemble kernel's CUDA text,
   compiled as C++ by the system compiler with these definitions, runs its __global__
   entry for every (block, thread) of a launch of 128-thread blocks in turn. */
extern "C" int sc_emulated_launch(SC_ENTRY_ARGS, int threads_per_block) {
    blockDim.x = (unsigned)threads_per_block;
    gridDim.x = (unsigned)((runs + threads_per_block - 1) / threads_per_block);
    for (blockIdx.x = 0; blockIdx.x < gridDim.x; blockIdx.x++)
        for (threadIdx.x = 0; threadIdx.x < blockDim.x; threadIdx.x++)
            springc_ensemble(SC_ENTRY_NAMES);
    return 0;
}

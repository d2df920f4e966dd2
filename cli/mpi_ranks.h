/*
 * mpi_ranks.h -- the program's MPI part (mpi.c, built with RADIOSITY_MPI):
 * start, the ranks' messages for the streamed view factors, stop.
 */
#ifndef RAD_CLI_MPI_RANKS_H
#define RAD_CLI_MPI_RANKS_H

#include "radiosity.h"

/* Start MPI when a launcher (mpirun) started this process, and fill
 * *ranks (rank, size, the send / receive callbacks); without a launcher
 * MPI is not started and *ranks is {0, 1}.  Returns the number of ranks,
 * -1 when MPI failed to start. */
int cli_mpi_start(int *argc, char ***argv, rad_stream_ranks *ranks);

/* Finalize MPI if it was started; with a nonzero status end the whole job
 * (MPI_Abort: the other ranks may wait for this one).  Safe to call twice. */
void cli_mpi_stop(int status);

#endif

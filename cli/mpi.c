/*
 * mpi.c -- `mpirun -np N radiosity viewfactors ...`: the ranks' messages
 * for rad_scene_stream_view_factors (rad_stream_ranks).  Built only with
 * RADIOSITY_MPI (CMake finds Open MPI); the library itself needs no MPI.
 *
 * MPI starts only when a launcher started the program (its environment
 * names the job's size), so a plain `radiosity viewfactors` runs as it
 * always did, without MPI's start-up.  Each block is one message from its
 * rank to rank 0 (MPI_Send / MPI_Recv, in pieces of at most 2^30 doubles
 * for MPI's int counts); rank 0 receives the blocks in order.  A rank that
 * fails ends the whole job (MPI_Abort): the others would wait for it.
 */
#include "mpi_ranks.h"

#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>

enum { PIECE = 1 << 30 }; /* doubles per MPI call: its counts are int */

static int mpi_send(void *user, const double *data, size_t count)
{
    (void)user;
    for (size_t at = 0; at < count; at += PIECE) {
        int piece = (int)(count - at < PIECE ? count - at : PIECE);
        if (MPI_Send(data + at, piece, MPI_DOUBLE, 0, 0, MPI_COMM_WORLD) != MPI_SUCCESS)
            return 1;
    }
    return 0;
}

static int mpi_receive(void *user, int from, double *data, size_t count)
{
    (void)user;
    for (size_t at = 0; at < count; at += PIECE) {
        int piece = (int)(count - at < PIECE ? count - at : PIECE);
        if (MPI_Recv(data + at, piece, MPI_DOUBLE, from, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE) != MPI_SUCCESS)
            return 1;
    }
    return 0;
}

static int started;

int cli_mpi_start(int *argc, char ***argv, rad_stream_ranks *ranks)
{
    *ranks = (rad_stream_ranks){0, 1, NULL, NULL, NULL};
    /* Open MPI's mpirun, and PMI / PMIx launchers (Slurm, MPICH's hydra). */
    if (!getenv("OMPI_COMM_WORLD_SIZE") && !getenv("PMI_SIZE") && !getenv("PMIX_RANK"))
        return 1;
    int provided = 0;
    if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
        return -1;
    started = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &ranks->rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks->size);
    ranks->send = mpi_send;
    ranks->receive = mpi_receive;
    return ranks->size;
}

void cli_mpi_stop(int status)
{
    if (!started)
        return;
    started = 0;
    if (status != 0) {
        fflush(stdout);
        fflush(stderr);
        MPI_Abort(MPI_COMM_WORLD, status);
    }
    MPI_Finalize();
}

/* Everything porompm uses from PETSc: the SNES/KSP/PC stack, DMDA grids, options, logging, viewers. */
#include <petscsys.h>
#include <petscsnes.h>
#include <petscdmda.h>
#include <petscviewer.h>
#include <petsclog.h>
#include <petscversion.h>

//! NRRD and raw volume files (written by a helper).

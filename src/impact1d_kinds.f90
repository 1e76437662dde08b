!> Working precision for the whole core: IEEE double, as the f2py layer passes c_double.
module impact1d_kinds
  use, intrinsic :: iso_fortran_env, only: real64
  implicit none
  private
  public :: wp, eps_wp

  integer, parameter :: wp = real64
  !> Unit roundoff of wp; every solver tolerance is a named multiple of it.
  real(wp), parameter :: eps_wp = epsilon(1.0_wp)
end module impact1d_kinds

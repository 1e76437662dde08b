!> The width of the engine's two-body kernels. The model and the state hold the bodies in
!> arrays of N; the kernels that run per step or per event (the mode solve, the RK4 step and
!> its location, the event point, the springs) take them in max_lanes lanes: fixed-size
!> arrays that the compiler keeps in registers, two bodies in one SIMD register. On arrays of
!> run-time size the steps of the sine and spring bench scenes took 1.5 and 2 times as long
!> and an event point twice as long (descriptors, calls not inlined, copies through memcpy).
!> A one-body scene leaves its second lane idle at 0 (docs/architecture.md, "Model, state
!> and lanes").
!> Scenes have at most max_lanes bodies until the cluster solver (issue 19, stage 4).
module impact1d_lanes
  use impact1d_kinds, only: wp
  implicit none
  private
  public :: max_lanes, to_lanes

  integer, parameter :: max_lanes = 2

contains

  !> y (N <= max_lanes) in lanes, the idle ones 0.
  pure subroutine to_lanes(y, lanes)
    real(wp), contiguous, intent(in) :: y(:)
    real(wp), intent(out) :: lanes(max_lanes)
    integer :: i
    ! A loop of max_lanes trips: unrolled into moves (a loop of size(y) trips became a call to
    ! memcpy, ~5 ns a step for each of a step's copies).
    do i = 1, max_lanes
      lanes(i) = 0.0_wp
      if (i <= size(y)) lanes(i) = y(i)
    end do
  end subroutine to_lanes
end module impact1d_lanes

!> The applied forces: everything on the bodies but contact and friction. The external
!> forces f(t) always; the springs' and dampers' (which depend on the state) only when the
!> scene names them, so a scene without them computes exactly what it did before.
!> In lanes (impact1d_lanes), into arrays of the caller's: nothing here allocates.
module impact1d_loads
  use impact1d_kinds, only: wp
  use impact1d_lanes, only: max_lanes
  use impact1d_scene, only: scene_type
  use impact1d_state, only: lane_state_type
  implicit none
  private
  public :: applied_force, applied_rate, state_force

contains

  !> Applied forces f at time t, positions x + dx (dx: low parts and stage displacements)
  !> and velocities v.
  pure subroutine applied_force(scene, t, x, dx, v, f)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t, x(max_lanes), dx(max_lanes), v(max_lanes)
    real(wp), intent(out) :: f(max_lanes)
    call scene%forcing%force(t, f)
    if (scene%springs%present) call scene%springs%add_force(x, dx, v, f)
  end subroutine applied_force

  !> Right derivative df of the applied forces in time, at velocities v.
  pure subroutine applied_rate(scene, t, v, df)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t, v(max_lanes)
    real(wp), intent(out) :: df(max_lanes)
    call scene%forcing%rate(t, df)
    if (scene%springs%present) call scene%springs%add_force_rate(v, df)
  end subroutine applied_rate

  !> Applied forces f in state s.
  pure subroutine state_force(scene, s, f)
    type(scene_type), intent(in) :: scene
    type(lane_state_type), intent(in) :: s
    real(wp), intent(out) :: f(max_lanes)
    call applied_force(scene, s%t, s%x, s%x_lo, s%v, f)
  end subroutine state_force
end module impact1d_loads

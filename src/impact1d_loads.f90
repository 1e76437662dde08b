!> The applied forces: everything on the bodies but contact and friction. The external
!> forces f(t) always; the springs' and dampers' (which depend on the state) only when the
!> scene names them, so a scene without them computes exactly what it did before.
module impact1d_loads
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type
  use impact1d_state, only: state_type
  implicit none
  private
  public :: applied_force, applied_rate, state_force

contains

  !> Applied forces at time t, positions x + dx (dx: low parts and stage displacements) and
  !> velocities v.
  pure function applied_force(scene, t, x, dx, v) result(f)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t, x(2), dx(2), v(2)
    real(wp) :: f(2)
    f = scene%forcing%force(t)
    if (scene%springs%present) f = f + scene%springs%force(x, dx, v)
  end function applied_force

  !> Right derivative of the applied forces in time, at velocities v.
  pure function applied_rate(scene, t, v) result(df)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t, v(2)
    real(wp) :: df(2)
    df = scene%forcing%rate(t)
    if (scene%springs%present) df = df + scene%springs%force_rate(v)
  end function applied_rate

  !> Applied forces in state s.
  pure function state_force(scene, s) result(f)
    type(scene_type), intent(in) :: scene
    type(state_type), intent(in) :: s
    real(wp) :: f(2)
    f = applied_force(scene, s%t, s%x, s%x_lo, s%v)
  end function state_force
end module impact1d_loads

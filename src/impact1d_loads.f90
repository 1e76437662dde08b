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
  public :: applied_force, applied_rate, state_force, add_stop_force, stop_potential, stop_gap, &
    stop_release_loss

contains

  !> Applied forces f at time t, positions x + dx (dx: low parts and stage displacements)
  !> and velocities v (without the compliant stops': add_stop_force adds the engaged ones'.
  !> Apart, so that this stays small enough to be inlined where it is hot).
  pure subroutine applied_force(scene, t, x, dx, v, f)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t, x(max_lanes), dx(max_lanes), v(max_lanes)
    real(wp), intent(out) :: f(max_lanes)
    call scene%forcing%force(t, f)
    if (scene%springs%present) call scene%springs%add_force(x, dx, v, f)
  end subroutine applied_force

  !> Gap of compliant stop row r at positions x + dx (negative: its penetration p = -gap).
  pure real(wp) function stop_gap(scene, r, x, dx)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: r
    real(wp), intent(in) :: x(max_lanes), dx(max_lanes)
    associate (n => scene%pair%normal(:, r))
      stop_gap = ((n(1) * x(1) + n(2) * x(2)) + scene%row_offset(r)) + (n(1) * dx(1) + n(2) * dx(2))
    end associate
  end function stop_gap

  !> f += the engaged stops' forces: each pushes its ends apart along its row's normal with
  !> F = k p + c p' = -(k gap + c gap') (docs/method.md section 10), the force of a spring
  !> and damper whose rest is the limit. Released at F = 0, so F >= 0 while engaged.
  pure subroutine add_stop_force(scene, engaged, x, dx, v, f)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: engaged
    real(wp), intent(in) :: x(max_lanes), dx(max_lanes), v(max_lanes)
    real(wp), intent(inout) :: f(max_lanes)
    integer :: j, r
    do j = 1, scene%n_stops
      if (.not. btest(engaged, j - 1)) cycle
      r = scene%n_rows + j
      associate (n => scene%pair%normal(:, r))
        f = f - n * (scene%row_k(r) * stop_gap(scene, r, x, dx) + scene%row_c(r) * (n(1) * v(1) + n(2) * v(2)))
      end associate
    end do
  end subroutine add_stop_force

  !> The stops' stored energy at positions x + dx: k p^2 / 2 wherever p = -gap > 0, engaged
  !> or not (a function of the positions, as a spring's is).
  pure real(wp) function stop_potential(scene, x, dx) result(pe)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: x(max_lanes), dx(max_lanes)
    integer :: r
    pe = 0.0_wp
    do r = scene%n_rows + 1, scene%n_rows + scene%n_stops
      pe = pe + 0.5_wp * scene%row_k(r) * min(0.0_wp, stop_gap(scene, r, x, dx))**2
    end do
  end function stop_potential

  !> What the stops not engaged lost from positions x_a + dx_a to x_b + dx_b: released
  !> inside (p > 0, k p + c p' < 0) a stop pushes on nothing while its stored k p^2 / 2
  !> falls, so that fall is its damping's loss, exactly (no quadrature over the instant p
  !> reaches 0 within the step, where the loss rate -k p p' has a kink).
  pure real(wp) function stop_release_loss(scene, engaged, x_a, dx_a, x_b, dx_b) result(loss)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: engaged
    real(wp), dimension(max_lanes), intent(in) :: x_a, dx_a, x_b, dx_b
    integer :: j, r
    loss = 0.0_wp
    do j = 1, scene%n_stops
      if (btest(engaged, j - 1)) cycle
      r = scene%n_rows + j
      loss = loss + 0.5_wp * scene%row_k(r) * (min(0.0_wp, stop_gap(scene, r, x_a, dx_a))**2 - &
        min(0.0_wp, stop_gap(scene, r, x_b, dx_b))**2)
    end do
  end function stop_release_loss

  !> Right derivative df of the applied forces in time, at velocities v.
  pure subroutine applied_rate(scene, t, v, df)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t, v(max_lanes)
    real(wp), intent(out) :: df(max_lanes)
    call scene%forcing%rate(t, df)
    if (scene%springs%present) call scene%springs%add_force_rate(v, df)
  end subroutine applied_rate

  !> Applied forces f in state s, the engaged compliant stops' included (engaged: a mode's).
  pure subroutine state_force(scene, s, f, engaged)
    type(scene_type), intent(in) :: scene
    type(lane_state_type), intent(in) :: s
    real(wp), intent(out) :: f(max_lanes)
    integer, intent(in) :: engaged
    call applied_force(scene, s%t, s%x, s%x_lo, s%v, f)
    if (engaged /= 0) call add_stop_force(scene, engaged, s%x, s%x_lo, s%v, f)
  end subroutine state_force
end module impact1d_loads

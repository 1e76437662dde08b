!> Springs and dampers of an N-body scene (docs/method.md, "Springs and dampers"), read from
!> the model's element records (scene_type's element_*): element j pulls its ends a, b (0 the
!> ground, at x = 0) together with tension k ((x_b - x_a) - rest) + c (v_b - v_a). The
!> engine's only springs (the two-body kernels' lanes, impact1d_springs, are gone): the
!> ends are looked up by index, so a chain's cost is its number of elements, not N^2.
!> An element whose ground end moves (scene%element_drive) acts on x_b - w(t) and v_b - w'(t)
!> when the time t is passed (every N-body engine call passes it when the scene has drives).
!> The compliant stops (docs/method.md section 10) are elements of the same kind on their
!> rows (scene%row_*, n_rows + 1 .. n_rows + n_stops): while engaged, a stop pushes its ends
!> apart along the row's normal with F = k p + c p' >= 0 (p = -gap, its penetration; a
!> moving ground end at w(t) as for the rows: gap = n_b (x_b - w) + offset). Which are
!> engaged is the event point's to switch (impact1d_nbody_event), so F stays a smooth
!> function of the state over a step.
module impact1d_elements
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type
  implicit none
  private
  public :: add_element_forces, add_moving_element_forces, add_element_rates, element_potential, &
    element_damping_power
  public :: stop_gap, stop_rate, add_stop_forces, add_stop_rates, stop_potential, stop_damping_power, &
    stop_release_loss, stop_drive_power

contains

  !> y at end e of an element or row (0: the ground, where y is 0).
  pure real(wp) function at_end(y, e)
    real(wp), intent(in) :: y(:)
    integer, intent(in) :: e
    at_end = 0.0_wp
    if (e > 0) at_end = y(e)
  end function at_end

  !> Element j's ground end's position (order 0) or velocity (1) at t when it moves, else 0.
  pure real(wp) function anchor(scene, j, order, t)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j, order
    real(wp), intent(in), optional :: t
    anchor = 0.0_wp
    if (.not. present(t) .or. scene%drives%n == 0) return
    anchor = drive_at(scene, scene%element_drive(j), order, t)
  end function anchor

  !> Drive d's position (order 0) or velocity (1) at t; 0 for d = 0 (a still ground).
  pure real(wp) function drive_at(scene, d, order, t)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: d, order
    real(wp), intent(in) :: t
    drive_at = 0.0_wp
    if (d == 0) return
    if (order == 0) then
      drive_at = scene%drives%position(d, t)
    else
      drive_at = scene%drives%velocity(d, t)
    end if
  end function drive_at

  !> Element j's elongation at positions x + dx (dx: low parts and stage displacements,
  !> added after the large terms cancel).
  pure real(wp) function elongation(scene, j, x, dx)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j
    real(wp), intent(in) :: x(:), dx(:)
    associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
      elongation = ((at_end(x, b) - at_end(x, a)) - scene%element_rest(j)) + (at_end(dx, b) - at_end(dx, a))
    end associate
  end function elongation

  !> elongation at time t, a moving ground end where it is then, and with the element's gear
  !> ratio n: (x_b - n x_a) - rest (docs/method.md section 14; n = 1 leaves the same bits).
  pure real(wp) function moving_elongation(scene, j, x, dx, t) result(elongation)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j
    real(wp), intent(in) :: x(:), dx(:), t
    elongation = geared_elongation(scene%element_body(:, j), scene%element_ratio(j), scene%element_rest(j), x, dx, &
      anchor(scene, j, 0, t))
  end function moving_elongation

  !> The elongation ((x_b - n x_a) - rest) + (dx_b - n dx_a) of an element with ends ab(1:2)
  !> and ratio n, a ground end (a = 0) at w (0 for a still one: x_b - 0 is x_b).
  pure real(wp) function geared_elongation(ab, n, rest, x, dx, w) result(elongation)
    integer, intent(in) :: ab(2)
    real(wp), intent(in) :: n, rest, x(:), dx(:), w
    associate (a => ab(1), b => ab(2))
      if (a == 0) then
        elongation = ((x(b) - w) - rest) + dx(b)
      else
        elongation = ((x(b) - n * x(a)) - rest) + (dx(b) - n * dx(a))
      end if
    end associate
  end function geared_elongation

  !> The elongation rate v_b - n v_a of an element with ends ab(1:2) and ratio n, relative to
  !> a ground end moving at w'.
  pure real(wp) function geared_rate(ab, n, v, w_rate) result(rate)
    integer, intent(in) :: ab(2)
    real(wp), intent(in) :: n, v(:), w_rate
    rate = (at_end(v, ab(2)) - n * at_end(v, ab(1))) - w_rate
  end function geared_rate

  !> Element j's elongation rate at velocities v, v_b - n v_a, relative to a moving ground
  !> end at time t (optional: a still ground).
  pure real(wp) function elongation_rate(scene, j, v, t) result(rate)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j
    real(wp), intent(in) :: v(:)
    real(wp), intent(in), optional :: t
    rate = geared_rate(scene%element_body(:, j), scene%element_ratio(j), v, anchor(scene, j, 1, t))
  end function elongation_rate

  !> f += the elements' forces at positions x + dx and velocities v (a still ground; moving
  !> ones: add_moving_element_forces). Every stage of an N-body step calls it: its ends read
  !> once, a ground end's zeros left out (x(b) - 0 is x(b): elongation's bits), the arrays
  !> contiguous (no strides).
  pure subroutine add_element_forces(scene, x, dx, v, f)
    type(scene_type), intent(in) :: scene
    real(wp), contiguous, intent(in) :: x(:), dx(:), v(:)
    real(wp), contiguous, intent(inout) :: f(:)
    real(wp) :: tension
    integer :: j, a, b
    do j = 1, scene%n_elements
      a = scene%element_body(1, j)
      b = scene%element_body(2, j)
      if (a > 0) then
        tension = scene%element_k(j) * (((x(b) - x(a)) - scene%element_rest(j)) + (dx(b) - dx(a))) + &
          scene%element_c(j) * (v(b) - v(a))
        f(a) = f(a) + tension
      else
        tension = scene%element_k(j) * ((x(b) - scene%element_rest(j)) + dx(b)) + scene%element_c(j) * v(b)
      end if
      f(b) = f(b) - tension
    end do
  end subroutine add_element_forces

  !> add_element_forces at time t, moving ground ends where they are then, and geared
  !> elements (scene%geared: the tension T on x_b - n x_a pulls b by -T and a by +n T, the
  !> gradient of the elongation) (apart, so that the loop of a scene without them stays as
  !> it was: with a branch inside it, a 50-body spring chain's element forces took half as
  !> many instructions again); and, when asked, the power the moving ground ends put in
  !> through the elements: the tension pulls the anchor toward the body, which moves at w'.
  pure subroutine add_moving_element_forces(scene, x, dx, v, f, t, drive_power)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: x(:), dx(:), v(:), t
    real(wp), intent(inout) :: f(:)
    real(wp), intent(out), optional :: drive_power
    real(wp) :: power
    call moving_forces(scene, scene%n_elements, scene%element_body, scene%element_drive, scene%element_ratio, &
      scene%element_k, scene%element_c, scene%element_rest, x, dx, v, f, t, power)
    if (present(drive_power)) drive_power = power
  end subroutine add_moving_element_forces

  !> add_moving_element_forces' loop on the element records as arrays of their own (explicit
  !> shape: the drives' terms are called through a pointer (impact1d_drives' varying), which
  !> the compiler must assume writes memory, so that read through scene the loop reloaded
  !> each record array's descriptor at every element; with that and a second loop for the
  !> power, input/burridge_knopoff.nml to 2 s took 163.6 M instructions, now 143.0 M).
  pure subroutine moving_forces(scene, ne, body, drive, ratio, k, c, rest, x, dx, v, f, t, power)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: ne, body(2, ne), drive(ne)
    real(wp), intent(in) :: ratio(ne), k(ne), c(ne), rest(ne), x(:), dx(:), v(:), t
    real(wp), intent(inout) :: f(:)
    real(wp), intent(out) :: power
    real(wp) :: tension, w, w_rate
    integer :: j
    power = 0.0_wp
    do j = 1, ne
      w = drive_at(scene, drive(j), 0, t)
      w_rate = drive_at(scene, drive(j), 1, t)
      tension = k(j) * geared_elongation(body(:, j), ratio(j), rest(j), x, dx, w) + c(j) * &
        geared_rate(body(:, j), ratio(j), v, w_rate)
      if (body(1, j) > 0) f(body(1, j)) = f(body(1, j)) + ratio(j) * tension
      f(body(2, j)) = f(body(2, j)) - tension
      if (drive(j) > 0) power = power - tension * w_rate
    end do
  end subroutine moving_forces

  !> df += the rate of the spring forces at velocities v (at time t: relative to a moving
  !> ground end; the dampers' part needs the accelerations: left out, as impact1d_springs
  !> did, deleted with the two-body engine).
  pure subroutine add_element_rates(scene, v, df, t)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: v(:)
    real(wp), intent(inout) :: df(:)
    real(wp), intent(in), optional :: t
    real(wp) :: rate
    integer :: j
    do j = 1, scene%n_elements
      associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
        rate = scene%element_k(j) * elongation_rate(scene, j, v, t)
        if (a > 0) df(a) = df(a) + scene%element_ratio(j) * rate
        df(b) = df(b) - rate
      end associate
    end do
  end subroutine add_element_rates

  !> Potential energy stored in the springs at positions x + dx (at time t: moving ground
  !> ends where they are then, geared elements on x_b - n x_a).
  pure real(wp) function element_potential(scene, x, dx, t) result(pe)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: x(:), dx(:)
    real(wp), intent(in), optional :: t
    integer :: j
    pe = 0.0_wp
    if (present(t)) then
      do j = 1, scene%n_elements
        pe = pe + scene%element_k(j) * moving_elongation(scene, j, x, dx, t)**2
      end do
    else
      do j = 1, scene%n_elements
        pe = pe + scene%element_k(j) * elongation(scene, j, x, dx)**2
      end do
    end if
    pe = 0.5_wp * pe
  end function element_potential

  !> Power the dampers dissipate at velocities v (at time t: on the velocity relative to a
  !> moving ground end, geared elements' on v_b - n v_a).
  pure real(wp) function element_damping_power(scene, v, t) result(power)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: v(:)
    real(wp), intent(in), optional :: t
    integer :: j
    power = 0.0_wp
    if (present(t)) then
      power = moving_damping_power(scene, scene%n_elements, scene%element_body, scene%element_drive, &
        scene%element_ratio, scene%element_c, v, t)
      return
    end if
    do j = 1, scene%n_elements
      associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
        power = power + scene%element_c(j) * (at_end(v, b) - at_end(v, a))**2
      end associate
    end do
  end function element_damping_power

  !> element_damping_power at time t, on the record arrays as moving_forces takes them (its
  !> loop through scene reloaded their descriptors at every element, as moving_forces' did).
  pure real(wp) function moving_damping_power(scene, ne, body, drive, ratio, c, v, t) result(power)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: ne, body(2, ne), drive(ne)
    real(wp), intent(in) :: ratio(ne), c(ne), v(:), t
    integer :: j
    power = 0.0_wp
    do j = 1, ne
      power = power + c(j) * geared_rate(body(:, j), ratio(j), v, drive_at(scene, drive(j), 1, t))**2
    end do
  end function moving_damping_power

  !> Row r's ground end's position (order 0) or velocity (1) at t when it moves, else 0.
  pure real(wp) function row_anchor(scene, r, order, t)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: r, order
    real(wp), intent(in), optional :: t
    row_anchor = 0.0_wp
    if (.not. present(t) .or. scene%drives%n == 0) return
    row_anchor = drive_at(scene, scene%row_drive(r), order, t)
  end function row_anchor

  !> Compliant stop row r's gap at positions x + dx (at time t: a moving ground end where it
  !> is then); negative past its limit (the penetration p = -gap). The deleted two-body engine's
  !> impact1d_loads stop_gap had the same order of operations.
  pure real(wp) function stop_gap(scene, r, x, dx, t)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: r
    real(wp), intent(in) :: x(:), dx(:)
    real(wp), intent(in), optional :: t
    associate (a => scene%row_body(1, r), b => scene%row_body(2, r), n => scene%row_normal(:, r))
      stop_gap = ((n(1) * at_end(x, a) + n(2) * (x(b) - row_anchor(scene, r, 0, t))) + scene%row_offset(r)) + &
        (n(1) * at_end(dx, a) + n(2) * dx(b))
    end associate
  end function stop_gap

  !> The rate gap' of stop row r's gap at velocities v (at time t: relative to a moving
  !> ground end).
  pure real(wp) function stop_rate(scene, r, v, t)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: r
    real(wp), intent(in) :: v(:)
    real(wp), intent(in), optional :: t
    associate (a => scene%row_body(1, r), b => scene%row_body(2, r), n => scene%row_normal(:, r))
      stop_rate = n(1) * at_end(v, a) + n(2) * (v(b) - row_anchor(scene, r, 1, t))
    end associate
  end function stop_rate

  !> Engaged stop j's push F = k p + c p' = -(k gap + c gap') at positions x + dx,
  !> velocities v (time t). DESIGN's max(0, F) is kept by the switching: the location cuts
  !> the step where F falls to 0 and the event point releases the stop there, so F >= 0 at
  !> every state the run accepts. Clipped inside the step too, the trial step past the
  !> release would interpolate a kink, and the release be found less well (the damped
  !> thrown mass of tests/test_compliant_nbody.py at dt = 0.02: 2e-10 s from the two-body
  !> engine, which does not clip; unclipped, the same bits).
  pure real(wp) function stop_push(scene, j, x, dx, v, t)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j
    real(wp), intent(in) :: x(:), dx(:), v(:)
    real(wp), intent(in), optional :: t
    integer :: r
    r = scene%n_rows + j
    stop_push = -(scene%row_k(r) * stop_gap(scene, r, x, dx, t) + scene%row_c(r) * stop_rate(scene, r, v, t))
  end function stop_push

  !> f += the engaged stops' pushes along their rows' normals.
  pure subroutine add_stop_forces(scene, engaged, x, dx, v, f, t)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: engaged(:)
    real(wp), intent(in) :: x(:), dx(:), v(:)
    real(wp), intent(inout) :: f(:)
    real(wp), intent(in), optional :: t
    real(wp) :: push
    integer :: j, r
    do j = 1, scene%n_stops
      if (.not. engaged(j)) cycle
      r = scene%n_rows + j
      push = stop_push(scene, j, x, dx, v, t)
      if (scene%row_body(1, r) > 0) f(scene%row_body(1, r)) = f(scene%row_body(1, r)) + scene%row_normal(1, r) * push
      f(scene%row_body(2, r)) = f(scene%row_body(2, r)) + scene%row_normal(2, r) * push
    end do
  end subroutine add_stop_forces

  !> df += the rate of the engaged stops' spring parts, -k gap' along the normal (the
  !> dampers' part needs the accelerations: left out, as for the elements).
  pure subroutine add_stop_rates(scene, engaged, v, df, t)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: engaged(:)
    real(wp), intent(in) :: v(:)
    real(wp), intent(inout) :: df(:)
    real(wp), intent(in), optional :: t
    real(wp) :: rate
    integer :: j, r
    do j = 1, scene%n_stops
      if (.not. engaged(j)) cycle
      r = scene%n_rows + j
      rate = -scene%row_k(r) * stop_rate(scene, r, v, t)
      if (scene%row_body(1, r) > 0) df(scene%row_body(1, r)) = df(scene%row_body(1, r)) + scene%row_normal(1, r) * rate
      df(scene%row_body(2, r)) = df(scene%row_body(2, r)) + scene%row_normal(2, r) * rate
    end do
  end subroutine add_stop_rates

  !> The stops' stored energy at positions x + dx (time t): k p^2 / 2 wherever p > 0,
  !> engaged or not (a function of the positions, as a spring's is).
  pure real(wp) function stop_potential(scene, x, dx, t) result(pe)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: x(:), dx(:)
    real(wp), intent(in), optional :: t
    integer :: r
    pe = 0.0_wp
    do r = scene%n_rows + 1, scene%n_rows + scene%n_stops
      pe = pe + 0.5_wp * scene%row_k(r) * min(0.0_wp, stop_gap(scene, r, x, dx, t))**2
    end do
  end function stop_potential

  !> Power the engaged stops' dampers dissipate at velocities v (time t): c gap'^2.
  pure real(wp) function stop_damping_power(scene, engaged, v, t) result(power)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: engaged(:)
    real(wp), intent(in) :: v(:)
    real(wp), intent(in), optional :: t
    integer :: j, r
    power = 0.0_wp
    do j = 1, scene%n_stops
      if (.not. engaged(j)) cycle
      r = scene%n_rows + j
      power = power + scene%row_c(r) * stop_rate(scene, r, v, t)**2
    end do
  end function stop_damping_power

  !> What the stops not engaged lost from positions x_a + dx_a (time t_a) to x_b + dx_b
  !> (t_b): released inside (p > 0, k p + c p' < 0) a stop pushes on nothing while its
  !> stored k p^2 / 2 falls, so that fall is its damping's loss, exactly (as the deleted
  !> impact1d_loads' stop_release_loss).
  pure real(wp) function stop_release_loss(scene, engaged, x_a, dx_a, x_b, dx_b, t_a, t_b) result(loss)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: engaged(:)
    real(wp), intent(in) :: x_a(:), dx_a(:), x_b(:), dx_b(:)
    real(wp), intent(in), optional :: t_a, t_b
    integer :: j, r
    loss = 0.0_wp
    do j = 1, scene%n_stops
      if (engaged(j)) cycle
      r = scene%n_rows + j
      loss = loss + 0.5_wp * scene%row_k(r) * (min(0.0_wp, stop_gap(scene, r, x_a, dx_a, t_a))**2 - &
        min(0.0_wp, stop_gap(scene, r, x_b, dx_b, t_b))**2)
    end do
  end function stop_release_loss

  !> Power the moving ground ends put in through the engaged stops at positions x + dx,
  !> velocities v, time t: the stop pushes its ground end (coefficient -n_b) with -n_b F, so
  !> the ground, moving at w', does n_b F w' on it.
  pure real(wp) function stop_drive_power(scene, engaged, x, dx, v, t) result(power)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: engaged(:)
    real(wp), intent(in) :: x(:), dx(:), v(:), t
    integer :: j, r
    power = 0.0_wp
    do j = 1, scene%n_stops
      r = scene%n_rows + j
      if (.not. engaged(j) .or. scene%row_drive(r) == 0) cycle
      power = power + scene%row_normal(2, r) * stop_push(scene, j, x, dx, v, t) * row_anchor(scene, r, 1, t)
    end do
  end function stop_drive_power
end module impact1d_elements

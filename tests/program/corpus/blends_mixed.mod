MODULE BlendsMixed
    ! MoveL -> MoveJ -> MoveL joined by zones of every size, fine and z0 between.
    CONST robtarget pA := [[375, 0, 540], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pB := [[300, 150, 400], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pC := [[300, -150, 400], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        MoveL pA, v500, z10, tool0;
        MoveJ pB, v1000, z50, tool0;
        MoveL pC, v300, z0, tool0;
        MoveJ pA, v1000, z200, tool0;
        MoveL pB, v200, fine, tool0;
        MoveJ pC, v800 \V:=650, z20 \Z:=15, tool0;
        MoveL pA, v100 \T:=2.5, fine, tool0;
    ENDPROC
ENDMODULE
